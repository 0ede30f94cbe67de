#include "dynamics.hpp"

// Eigen's solvers, instantiated in this file only. Compiled for AVX-512 (-march=native on
// such a processor) GCC 12 warns inside them: -Warray-bounds for the 8-double packet
// stores of SVDBase::_solve_impl into its temporary of at most 3 doubles (on a branch
// taken only for vectors of 8 or more, which GCC cannot rule out), and
// -Wmaybe-uninitialized for the `__m256d __Y = __Y;` of the compiler's own
// _mm256_undefined_pd(), which Eigen's AVX-512 sums (predux) reach in the Householder
// steps of both solvers (GCC 13 no longer warns). Neither is a defect of this code; the
// exemption covers the text of these headers, where the warnings arise, so this file's own
// code is still checked.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
#ifndef __clang__  // GCC's name: clang would warn about an unknown option
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#pragma GCC diagnostic pop
#include <algorithm>
#include <cmath>
#include <unsupported/Eigen/AutoDiff>

namespace superball {

namespace {

// Forward mode: each number carries its gradient with respect to (xi, U, W).
using Dual = Eigen::AutoDiffScalar<Eigen::Vector3d>;

// Relative distance used to tell points apart (two runs converge on a cycle to ~1e-12).
constexpr double same_point_tolerance = 1e-8;
// An eigenvalue of D(G^k) this close to 1 marks a cycle that is not isolated.
constexpr double family_tolerance = 1e-6;

constexpr int newton_max_iterations = 100;
constexpr int newton_max_halvings = 40;

bool close(const CanonicalState<double>& a, const CanonicalState<double>& b)
{
    const Eigen::Vector3d va = as_vector(a);
    const Eigen::Vector3d vb = as_vector(b);
    return (va - vb).norm() <= same_point_tolerance * std::max(va.norm(), vb.norm());
}

// The residual of G^k(s) = s in the variables the solver works in, (log xi, U, W): xi is
// compared relatively. In plain differences the plane xi = 0 would look like a set of
// approximate fixed points, since G maps it into itself where the ball comes off the
// wall downward (boundary_planes.md): xi' - xi -> 0 there without xi' = xi. On the corner
// plane xi stays 0 and only (U, W) are unknowns.
Eigen::Vector3d log_residual(const CanonicalState<double>& s, const CanonicalState<double>& image, Domain domain)
{
    const double xi = domain == Domain::corner ? 0.0 : std::log(image.xi / s.xi);
    return {xi, image.U - s.U, image.W - s.W};
}

// Relative size of a residual: the xi part is relative already; U and W are compared with
// the size of (U, W).
double relative_size(const Eigen::Vector3d& r, const CanonicalState<double>& s)
{
    return std::max(std::abs(r(0)), r.tail<2>().norm() / std::hypot(s.U, s.W));
}

double relative_residual(const CanonicalState<double>& s, const ModelMatrices& m, int k, Domain domain)
{
    const auto image = iterate(s, m, k, domain);
    return image ? relative_size(log_residual(s, *image, domain), s) : HUGE_VAL;
}

}  // namespace

bool lexicographically_less(const CanonicalState<double>& a, const CanonicalState<double>& b)
{
    if (a.xi != b.xi) return a.xi < b.xi;
    if (a.U != b.U) return a.U < b.U;
    return a.W < b.W;
}

StepJacobian step_jacobian(const CanonicalState<double>& s, const ModelMatrices& m)
{
    const CanonicalState<Dual> c{Dual(s.xi, 3, 0), Dual(s.U, 3, 1), Dual(s.W, 3, 2)};
    const CanonicalStep<Dual> r = canonical_map(c, m);
    StepJacobian j;
    j.step = {{r.next.xi.value(), r.next.U.value(), r.next.W.value()}, r.lambda.value()};
    j.dG.row(0) = r.next.xi.derivatives().transpose();
    j.dG.row(1) = r.next.U.derivatives().transpose();
    j.dG.row(2) = r.next.W.derivatives().transpose();
    j.dlambda = r.lambda.derivatives().transpose();
    return j;
}

IterateJacobian iterate_jacobian(const CanonicalState<double>& s, const ModelMatrices& m, int k, Domain domain)
{
    IterateJacobian r;
    r.state = s;
    for (int i = 0; i < k; ++i) {
        if (!in_domain(r.state, domain)) return r;
        const StepJacobian j = step_jacobian(r.state, m);
        // d(Lambda lambda) = dLambda lambda + Lambda dlambda D(G^i): the product rule, with
        // the new factor's gradient carried back to s by the chain rule.
        r.dlambda = r.dlambda * j.step.lambda + r.lambda * j.dlambda * r.dG;
        r.lambda *= j.step.lambda;
        r.dG = j.dG * r.dG;
        r.state = j.step.next;
    }
    r.in_region = in_domain(r.state, domain);
    return r;
}

std::optional<CanonicalState<double>> iterate(const CanonicalState<double>& s, const ModelMatrices& m, int k,
                                              Domain domain)
{
    CanonicalState<double> c = s;
    for (int i = 0; i < k; ++i) {
        if (!in_domain(c, domain)) return std::nullopt;
        c = canonical_map(c, m).next;
    }
    if (!in_domain(c, domain)) return std::nullopt;
    return c;
}

std::optional<std::array<std::complex<double>, 3>> sorted_eigenvalues(const Eigen::Matrix3d& a)
{
    const Eigen::EigenSolver<Eigen::Matrix3d> solver(a, false);
    if (solver.info() != Eigen::Success) return std::nullopt;
    std::array<std::complex<double>, 3> ev;
    for (int i = 0; i < 3; ++i) ev[static_cast<std::size_t>(i)] = solver.eigenvalues()(i);
    // Ties (complex pairs) by real part then imaginary part, so the order does not depend on
    // the eigensolver's.
    std::sort(ev.begin(), ev.end(), [](const std::complex<double>& x, const std::complex<double>& y) {
        if (std::abs(x) != std::abs(y)) return std::abs(x) > std::abs(y);
        if (x.real() != y.real()) return x.real() > y.real();
        return x.imag() > y.imag();
    });
    return ev;
}

std::string_view name(Stability s)
{
    switch (s) {
        case Stability::stable: return "stable";
        case Stability::unstable: return "unstable";
        case Stability::saddle: return "saddle";
        case Stability::marginal: return "marginal";
    }
    return "unknown";
}

Stability classify(std::span<const std::complex<double>> eigenvalues)
{
    int inside = 0, outside = 0;
    for (const auto& z : eigenvalues) {
        const double r = std::abs(z);
        if (r < 1.0 - marginal_tolerance) ++inside;
        if (r > 1.0 + marginal_tolerance) ++outside;
    }
    const int n = static_cast<int>(eigenvalues.size());
    if (inside == n) return Stability::stable;
    if (outside == n) return Stability::unstable;
    if (inside > 0 && outside > 0) return Stability::saddle;
    return Stability::marginal;
}

std::optional<CanonicalState<double>> newton_cycle(const CanonicalState<double>& start, const ModelMatrices& m, int k,
                                                   Domain domain)
{
    const bool corner = domain == Domain::corner;
    if (k < 1 || !(corner ? start.U < 0.0 && std::isfinite(start.W) : in_region(start))) return std::nullopt;
    // Unknowns (log xi, U, W): xi stays positive whatever the step, and the equation
    // log xi' = log xi cannot be met on the plane xi = 0 (see log_residual). On the corner
    // plane z(0) is unused: its residual and its row and column of the matrix are 0, so the
    // minimum-norm step leaves it alone.
    const auto state = [corner](const Eigen::Vector3d& z) {
        return CanonicalState<double>{corner ? 0.0 : std::exp(z(0)), z(1), z(2)};
    };
    Eigen::Vector3d z{corner ? 0.0 : std::log(start.xi), start.U, start.W};
    for (int it = 0; it < newton_max_iterations; ++it) {
        const CanonicalState<double> s = state(z);
        const IterateJacobian j = iterate_jacobian(s, m, k, domain);
        if (!j.in_region) return std::nullopt;
        const Eigen::Vector3d f = log_residual(s, j.state, domain);
        const double size = relative_size(f, s);
        if (!std::isfinite(size)) return std::nullopt;
        if (size <= newton_tolerance) return s;
        // D(G^k) in the variables (log xi, U, W): rows and columns of xi scaled.
        Eigen::Matrix3d a = j.dG;
        if (corner) {
            a.row(0).setZero();
            a.col(0).setZero();
        } else {
            a.row(0) /= j.state.xi;
            a.col(0) *= s.xi;
        }
        a -= Eigen::Matrix3d::Identity();
        if (corner) a(0, 0) = 0.0;
        // Minimum-norm solution of a d = -f: on a family of cycles `a` is singular at the
        // solution, and this step goes to the nearest member instead of along the family.
        const Eigen::Vector3d d = -a.jacobiSvd(Eigen::ComputeFullU | Eigen::ComputeFullV).solve(f);
        if (!d.allFinite()) return std::nullopt;
        // Backtracking: the full step may take an iterate of G^k out of the region (where G
        // is not the motion) or overshoot; halve until the residual decreases (Armijo).
        const double f_norm = f.norm();
        bool accepted = false;
        double t = 1.0;
        for (int h = 0; h < newton_max_halvings && !accepted; ++h, t *= 0.5) {
            const Eigen::Vector3d trial = z + t * d;
            const auto image = iterate(state(trial), m, k, domain);
            if (image && log_residual(state(trial), *image, domain).norm() <= (1.0 - 1e-4 * t) * f_norm) {
                z = trial;
                accepted = true;
            }
        }
        // No decrease: the residual is at the rounding level of G^k (cycles with large
        // eigenvalues amplify rounding) or the iteration is stuck; make_cycle's residual
        // check tells the two apart.
        if (!accepted) return size <= residual_tolerance ? std::optional(s) : std::nullopt;
    }
    return std::nullopt;
}

std::optional<Cycle> make_cycle(const CanonicalState<double>& point, const ModelMatrices& m, int k, Domain domain)
{
    if (k < 1 || !in_domain(point, domain)) return std::nullopt;
    // Minimal period: the smallest divisor d of k with G^d(point) = point.
    int period = k;
    for (int d = 1; d < k; ++d) {
        if (k % d == 0 && relative_residual(point, m, d, domain) <= residual_tolerance) {
            period = d;
            break;
        }
    }
    std::vector<CanonicalState<double>> orbit{point};
    for (int i = 1; i < period; ++i) {
        const auto next = iterate(orbit.back(), m, 1, domain);
        if (!next) return std::nullopt;
        orbit.push_back(*next);
    }
    const auto first = std::min_element(orbit.begin(), orbit.end(), lexicographically_less);
    std::rotate(orbit.begin(), first, orbit.end());

    const IterateJacobian j = iterate_jacobian(orbit.front(), m, period, domain);
    if (!j.in_region) return std::nullopt;
    Cycle c;
    c.period = period;
    c.corner = domain == Domain::corner;
    c.points = std::move(orbit);
    c.residual = relative_size(log_residual(c.points.front(), j.state, domain), c.points.front());
    if (!(c.residual <= residual_tolerance)) return std::nullopt;
    c.lambda = j.lambda;
    const auto eigenvalues = sorted_eigenvalues(j.dG);
    if (!eigenvalues) return std::nullopt;
    c.eigenvalues = *eigenvalues;
    c.stability = classify(c.eigenvalues);
    c.family = std::any_of(c.eigenvalues.begin(), c.eigenvalues.end(),
                           [](const std::complex<double>& z) { return std::abs(z - 1.0) < family_tolerance; });
    return c;
}

bool same_cycle(const Cycle& a, const Cycle& b)
{
    if (a.period != b.period || a.corner != b.corner || a.points.empty() || b.points.empty()) return false;
    // Any point, not just the representatives: two points of a cycle with nearly equal xi
    // may swap roles between two runs.
    return std::any_of(a.points.begin(), a.points.end(), [&](const auto& p) { return close(p, b.points.front()); });
}

std::vector<Cycle> distinct_cycles(std::span<const Cycle> cycles)
{
    std::vector<Cycle> kept;
    for (const Cycle& c : cycles) {
        if (std::none_of(kept.begin(), kept.end(), [&](const Cycle& k) { return same_cycle(k, c); })) kept.push_back(c);
    }
    std::stable_sort(kept.begin(), kept.end(), [](const Cycle& a, const Cycle& b) {
        if (a.corner != b.corner) return b.corner;
        if (a.period != b.period) return a.period < b.period;
        return lexicographically_less(a.points.front(), b.points.front());
    });
    return kept;
}

CanonicalState<double> SeededStarts::next()
{
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // Three draws per start whatever happens, so start i depends on i only.
    const double xi = unit(rng_);
    const double U = -std::pow(10.0, -2.0 + 4.0 * unit(rng_));
    const double W = 3.0 * std::max(1.0, -U) * (2.0 * unit(rng_) - 1.0);
    // unit() may return exactly 0; such a start is moved off the plane xi = 0.
    return {xi > 0.0 ? xi : 0.5, U, W};
}

std::vector<CanonicalState<double>> seeded_starts(std::uint64_t seed, std::uint64_t count)
{
    SeededStarts draw(seed);
    std::vector<CanonicalState<double>> starts;
    starts.reserve(count);
    while (starts.size() < count) starts.push_back(draw.next());
    return starts;
}

std::vector<Cycle> find_cycles(const ModelMatrices& m, int max_period, std::uint64_t starts, std::uint64_t seed,
                               Domain domain)
{
    std::vector<Cycle> found;
    for (const CanonicalState<double>& start : seeded_starts(seed, starts)) {
        for (int k = 1; k <= max_period; ++k) {
            if (const auto p = newton_cycle(start, m, k, domain)) {
                if (auto c = make_cycle(*p, m, k, domain)) found.push_back(std::move(*c));
            }
        }
    }
    return distinct_cycles(found);
}

}  // namespace superball
