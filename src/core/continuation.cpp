#include "continuation.hpp"

#include "boundary_planes.hpp"
#include "input.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unsupported/Eigen/AutoDiff>

namespace superball {

namespace {

using Vector4 = Eigen::Vector4d;
// Forward mode: each number carries its gradient with respect to (xi, U, W, p).
using Dual4 = Eigen::AutoDiffScalar<Vector4>;

// Test functions (normalised to [-1, 1]) smaller than this are rounding noise: no sign.
constexpr double significance = 1e-9;
// The bounds of the parameter count as reached this far beyond them (so a start on a bound,
// or a branch that stays on it up to rounding, is not at its end).
constexpr double bound_slack = 1e-12;
// Newton's method of the corrector: iterations, and the step size that counts as converged.
constexpr int corrector_iterations = 10;
constexpr double corrector_tolerance = 1e-12;
// Largest residual |G^k(x) - x| of an accepted point.
constexpr double accepted_residual = 1e-10;
// Step control: an accepted step whose corrector took at most easy_iterations grows the
// next by `growth`; the tangent may turn by at most acos(min_tangent_cosine) per step.
constexpr int easy_iterations = 3;
constexpr double growth = 1.5;
constexpr double min_tangent_cosine = 0.9;
// Event location: the bracket in arclength is narrowed to this (relative to the step).
constexpr double location_tolerance = 1e-11;
constexpr int location_iterations = 200;
// Near a branch point the corrector's matrix is nearly singular and Newton's method slows
// down to linear convergence: the location allows it more iterations than a step.
constexpr int location_corrector_iterations = 60;
// A located event is confirmed by an eigenvalue of D(G^k) this close to 1, -1 or the unit
// circle.
constexpr double confirmation_tolerance = 1e-6;
// A grip-slide switch (a kink of the branch) counts as located where its test function is
// this small: a jump of the corrector to another solution brackets a discontinuity instead,
// where the test stays large.
constexpr double switch_tolerance = 1e-7;

// Which coefficient of a surface a parameter sets.
enum class Kind : std::uint8_t { e, alpha, mu, inertia };

Kind kind_of(Parameter p)
{
    switch (p) {
        case Parameter::e:
        case Parameter::e_wall:
        case Parameter::e_floor: return Kind::e;
        case Parameter::alpha:
        case Parameter::alpha_wall:
        case Parameter::alpha_floor: return Kind::alpha;
        case Parameter::mu:
        case Parameter::mu_wall:
        case Parameter::mu_floor: return Kind::mu;
        case Parameter::inertia: return Kind::inertia;
    }
    return Kind::e;
}

// Whether the parameter sets the wall's (floor's) coefficient: the shared ones set both.
bool sets_surface(Parameter p, bool wall)
{
    switch (p) {
        case Parameter::e_wall:
        case Parameter::alpha_wall:
        case Parameter::mu_wall: return wall;
        case Parameter::e_floor:
        case Parameter::alpha_floor:
        case Parameter::mu_floor: return !wall;
        case Parameter::inertia: return false;
        default: return true;
    }
}

double& coefficient(Surface& s, Kind k) { return k == Kind::e ? s.e : k == Kind::alpha ? s.alpha : s.mu; }

// The impact matrices along the path at s = value, each coefficient carrying its
// derivative in s (the fourth independent variable).
BasicModelMatrices<Dual4> dual_matrices(const ParameterPath& path, double value)
{
    const auto coefficient = [value](double origin, double direction) {
        Dual4 c(origin + value * direction);
        c.derivatives()(3) = direction;
        return c;
    };
    const Dual4 inertia = coefficient(path.origin.inertia, path.direction.inertia);
    const auto matrix = [&](const Surface& o, const Surface& d) {
        return BasicImpactMatrix<Dual4>::of(coefficient(o.e, d.e), coefficient(o.alpha, d.alpha), inertia,
                                            coefficient(o.mu, d.mu));
    };
    return {matrix(path.origin.wall, path.direction.wall), matrix(path.origin.floor, path.direction.floor),
            path.at(value).frictional()};
}

CanonicalState<double> value_of(const CanonicalState<Dual4>& c) { return {c.xi.value(), c.U.value(), c.W.value()}; }

// det(m) divided by Hadamard's bound, the product of the rows' norms: in [-1, 1].
template <int N>
double normalised_determinant(const Eigen::Matrix<double, N, N>& m)
{
    const double bound = m.rowwise().norm().prod();
    return bound > 0.0 ? m.determinant() / bound : 0.0;
}

// Second compound (bialternate product A (.) A) of a 3 x 3 matrix: its 2 x 2 minors, whose
// eigenvalues are the products mu_i mu_j of pairs of A's eigenvalues.
Eigen::Matrix3d second_compound(const Eigen::Matrix3d& a)
{
    constexpr int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    Eigen::Matrix3d c;
    for (int r = 0; r < 3; ++r) {
        for (int s = 0; s < 3; ++s) {
            const int i = pairs[r][0], j = pairs[r][1], k = pairs[s][0], l = pairs[s][1];
            c(r, s) = a(i, k) * a(j, l) - a(i, l) * a(j, k);
        }
    }
    return c;
}

// ---- The branch equations ------------------------------------------------------------

struct System {
    ParameterPath path;
    int period;
    bool corner;  // on the plane xi = 0: the equation for xi is xi = 0
};

// The branch equations H = 0 and their Jacobian. The equation for xi is written as
// xi_k / xi - 1 = 0 (xi_k: the xi of G^k): where the wall sends the ball down, xi_k = xi K
// with K analytic through xi = 0 (boundary_planes.md), so this equation is analytic there
// and, unlike xi_k - xi = 0, is not solved by the whole plane's branch of corner cycles
// (at xi = 0 it reads kappa = 1). A branch that reaches the plane then crosses it at a
// regular point, where the corrector cannot slide onto the corner branch, and its crossing
// is located as the zero of xi. On the corner plane itself the equation is xi = 0.
struct Evaluation {
    ParameterJacobian g;
    Eigen::Vector3d H;             // (xi_k / xi - 1, U_k - U, W_k - W); corner: (xi, U_k - U, W_k - W)
    Eigen::Matrix<double, 3, 4> J;  // [H_x H_p]
};

std::optional<Evaluation> evaluate(const System& sys, const Vector4& y)
{
    Evaluation e;
    e.g = parameter_jacobian(as_state(y.head<3>()), sys.path, y(3), sys.period);
    if (!e.g.finite) return std::nullopt;
    e.H = as_vector(e.g.image) - y.head<3>();
    e.J.leftCols<3>() = e.g.dG - Eigen::Matrix3d::Identity();
    e.J.col(3) = e.g.dG_dp;
    if (sys.corner) {
        e.H(0) = y(0);
        e.J.row(0) = Eigen::RowVector4d(1.0, 0.0, 0.0, 0.0);
    } else {
        const double xi = y(0);
        if (xi == 0.0) return std::nullopt;
        e.H(0) = e.g.image.xi / xi - 1.0;
        e.J.row(0).head<3>() = e.g.dG.row(0) / xi;
        e.J(0, 0) -= e.g.image.xi / (xi * xi);
        e.J(0, 3) = e.g.dG_dp(0) / xi;
    }
    if (!e.H.allFinite() || !e.J.allFinite()) return std::nullopt;
    return e;
}

// A solved point of the branch with its unit tangent.
struct Node {
    Vector4 y;
    Vector4 t;
    Evaluation ev;
    int iterations = 0;
};

// The null vector of a 3 x 4 matrix of rank 3: its signed 3 x 3 minors (the generalised cross
// product). Zero when the rank is lower.
Vector4 null_vector(const Eigen::Matrix<double, 3, 4>& J)
{
    Vector4 t;
    for (int j = 0; j < 4; ++j) {
        Eigen::Matrix3d minor;
        for (int c = 0, k = 0; c < 4; ++c) {
            if (c != j) minor.col(k++) = J.col(c);
        }
        t(j) = (j % 2 == 0 ? 1.0 : -1.0) * minor.determinant();
    }
    return t;
}

// Unit null vector of J, oriented so that t . orientation > 0: the solution of
// [J; orientation^T] z = (0, 0, 0, 1), normalised.
std::optional<Vector4> tangent(const System& sys, const Eigen::Matrix<double, 3, 4>& J, const Vector4& orientation)
{
    Eigen::Matrix4d a;
    a.topRows<3>() = J;
    a.row(3) = orientation.transpose();
    Vector4 z = a.fullPivLu().solve(Vector4(0.0, 0.0, 0.0, 1.0));
    if (sys.corner) z(0) = 0.0;
    const double n = z.norm();
    if (!(n > 0.0) || !z.allFinite()) return std::nullopt;
    return Vector4(z / n);
}

// Newton's method on H(y) = 0 and one more equation, from y; step(evaluation, y) is the
// Newton step. The converged point (residual within accepted_residual) carries its tangent,
// oriented along `orientation`.
template <class Step>
std::optional<Node> newton(const System& sys, Vector4 y, const Vector4& orientation, int iterations, const Step& step)
{
    for (int it = 1; it <= iterations; ++it) {
        if (sys.corner) y(0) = 0.0;
        const auto ev = evaluate(sys, y);
        if (!ev) return std::nullopt;
        const Vector4 d = step(*ev, y);
        if (!d.allFinite()) return std::nullopt;
        y += d;
        if (sys.corner) y(0) = 0.0;
        if (d.norm() <= corrector_tolerance * (1.0 + y.norm())) {
            auto last = evaluate(sys, y);
            if (!last || last->H.cwiseAbs().maxCoeff() > accepted_residual) return std::nullopt;
            const auto t = tangent(sys, last->J, orientation);
            if (!t) return std::nullopt;
            return Node{y, *t, std::move(*last), it};
        }
    }
    return std::nullopt;
}

// Newton's method on H(y) = 0 with the linear condition normal . y = level, from y.
std::optional<Node> correct(const System& sys, const Vector4& y, const Vector4& normal, double level,
                            const Vector4& orientation, int iterations = corrector_iterations)
{
    return newton(sys, y, orientation, iterations, [&](const Evaluation& ev, const Vector4& at) {
        Eigen::Matrix4d a;
        a.topRows<3>() = ev.J;
        a.row(3) = normal.transpose();
        Vector4 r;
        r.head<3>() = ev.H;
        r(3) = normal.dot(at) - level;
        return Vector4(a.fullPivLu().solve(-r));
    });
}

// The predictor-corrector step of arclength h from `a`.
std::optional<Node> step(const System& sys, const Node& a, double h, int iterations = corrector_iterations)
{
    return correct(sys, a.y + h * a.t, a.t, a.t.dot(a.y) + h, a.t, iterations);
}

// Natural-parameter Newton at p = value from y. Full pivoting: where H_x is singular to
// rounding (a family of cycles at fixed p, a fold on the bound) the step leaves the free
// direction alone.
std::optional<Node> solve_at_parameter(const System& sys, Vector4 y, double value, const Vector4& orientation)
{
    y(3) = value;
    return newton(sys, y, orientation, corrector_iterations, [](const Evaluation& ev, const Vector4&) {
        const Eigen::Matrix3d hx = ev.J.leftCols<3>();
        Vector4 d = Vector4::Zero();
        d.head<3>() = -hx.fullPivLu().solve(ev.H);
        return d;
    });
}

// ---- Test functions ---------------------------------------------------------------------

enum class TestKind : std::uint8_t {
    fold,
    branch,
    period_doubling,
    neimark_sacker,
    kappa,        // corner plane: transverse multiplier - 1
    wall_grip,    // psi* - psi of the wall impact from cycle point `point` (SPEC.md 1b)
    floor_grip,   // the same of its floor impact
    xi_zero,      // xi of cycle point `point`
    xi_one,       // 1 - xi
    U_zero,       // -U
    wall_down,    // corner plane: -p, the vertical velocity leaving the wall (the plane is
                  // invariant where p < 0, boundary_planes.md)
    lower_bound,  // p - min
    upper_bound,  // max - p
};

struct Test {
    TestKind kind;
    int point = 0;
};

bool terminal(TestKind k) { return k >= TestKind::xi_zero; }

std::vector<Test> tests_of(const System& sys)
{
    std::vector<Test> tests{{TestKind::fold}, {TestKind::branch}, {TestKind::period_doubling},
                            {TestKind::neimark_sacker}};
    if (sys.corner) tests.push_back({TestKind::kappa});
    for (int i = 0; i < sys.period; ++i) {
        if (!sys.corner) {
            tests.push_back({TestKind::xi_zero, i});
            tests.push_back({TestKind::xi_one, i});
        }
        tests.push_back({TestKind::U_zero, i});
        if (sys.corner) tests.push_back({TestKind::wall_down, i});
        tests.push_back({TestKind::wall_grip, i});
        tests.push_back({TestKind::floor_grip, i});
    }
    tests.push_back({TestKind::lower_bound});
    tests.push_back({TestKind::upper_bound});
    return tests;
}

double test_value(const System& sys, const Test& test, const Node& n, const ContinuationSettings& set)
{
    const Eigen::Matrix3d& dG = n.ev.g.dG;
    const auto point = [&]() -> const CanonicalState<double>& {
        return n.ev.g.orbit[static_cast<std::size_t>(test.point)];
    };
    switch (test.kind) {
        case TestKind::fold: return n.t(3);
        case TestKind::branch: {
            Eigen::Matrix4d a;
            a.topRows<3>() = n.ev.J;
            a.row(3) = n.t.transpose();
            return normalised_determinant<4>(a);
        }
        case TestKind::period_doubling:
            return normalised_determinant<3>(Eigen::Matrix3d(dG + Eigen::Matrix3d::Identity()));
        case TestKind::neimark_sacker:
            return normalised_determinant<3>(Eigen::Matrix3d(second_compound(dG) - Eigen::Matrix3d::Identity()));
        case TestKind::kappa: return dG(0, 0) - 1.0;
        case TestKind::xi_zero: return point().xi;
        case TestKind::xi_one: return 1.0 - point().xi;
        case TestKind::U_zero: return -point().U;
        case TestKind::wall_grip:
        case TestKind::floor_grip: {
            // An infinite mu: inf, never a sign change.
            const ModelMatrices m = ModelMatrices::of(sys.path.at(n.y(3)));
            const ImpactContacts ic = impact_contacts(point(), m);
            if (test.kind == TestKind::wall_grip) return m.wall.grip_ratio - std::abs(ic.s_wall) / ic.approach_wall;
            return m.floor.grip_ratio - std::abs(ic.s_floor) / ic.approach_floor;
        }
        case TestKind::wall_down: {
            const ModelMatrices m = ModelMatrices::of(sys.path.at(n.y(3)));
            return -plane_map_xi0(point().U, point().W, m).p;
        }
        case TestKind::lower_bound: return n.y(3) - set.min + bound_slack;
        case TestKind::upper_bound: return set.max - n.y(3) + bound_slack;
    }
    return 0.0;
}

std::vector<double> test_values(const System& sys, const std::vector<Test>& tests, const Node& n,
                                const ContinuationSettings& set)
{
    std::vector<double> v;
    v.reserve(tests.size());
    for (const Test& t : tests) v.push_back(test_value(sys, t, n, set));
    return v;
}

// -1, 0 (noise) or +1.
int significant_sign(const Test& t, double v)
{
    if (terminal(t.kind)) return v > 0.0 ? 1 : -1;
    if (std::abs(v) <= significance) return 0;
    return v > 0.0 ? 1 : -1;
}

// ---- Tracing a direction ----------------------------------------------------------------

struct Located {
    Node node;
    std::size_t after;  // index of the node the event follows
    double h;           // arclength from that node
    BranchEvent event;
    std::string note;
    double bracket;
};

struct Context {
    const System& sys;
    const ContinuationSettings& set;
    const std::vector<Test>& tests;
};

// The zero of test `j` on the step of arclength h from `a` (values fa at a, fb at h, of
// opposite signs): Illinois' variant of regula falsi on the arclength. Returns the bracket
// end with the smaller |value|, or for the terminal tests the end inside (value > 0).
struct Position {
    Node node;
    double h;        // arclength from the step's start
    double bracket;  // width of the final bracket in arclength: bounds the error in p
};

Position locate(const Context& c, std::size_t j, const Node& a, double h, double fa, const Node& b, double fb)
{
    const Test& test = c.tests[j];
    double lo = 0.0, hi = h;
    double f_lo = fa, f_hi = fb;      // Illinois-scaled values for the secant
    double v_lo = fa, v_hi = fb;      // true values
    Node n_lo = a, n_hi = b;
    int side = 0;
    for (int it = 0; it < location_iterations && hi - lo > location_tolerance * (1.0 + h); ++it) {
        double x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        // Bisection when the secant falls outside or on the bracket, or every fourth step
        // (keeps the bracket shrinking when one end is stuck).
        if (!(x > lo && x < hi) || it % 4 == 3) x = 0.5 * (lo + hi);
        auto n = step(c.sys, a, x, location_corrector_iterations);
        if (!n) {
            x = 0.5 * (lo + hi);
            n = step(c.sys, a, x, location_corrector_iterations);
            if (!n) break;
        }
        const double f = test_value(c.sys, test, *n, c.set);
        if (f == 0.0) {
            lo = hi = x;
            v_lo = v_hi = 0.0;
            n_lo = n_hi = *n;
            break;
        }
        if ((f > 0.0) == (v_lo > 0.0)) {
            lo = x;
            f_lo = v_lo = f;
            n_lo = std::move(*n);
            if (side == -1) f_hi *= 0.5;
            side = -1;
        } else {
            hi = x;
            f_hi = v_hi = f;
            n_hi = std::move(*n);
            if (side == 1) f_lo *= 0.5;
            side = 1;
        }
    }
    const double width = hi - lo;
    if (terminal(test.kind)) return v_lo > 0.0 ? Position{n_lo, lo, width} : Position{n_hi, hi, width};
    return std::abs(v_lo) <= std::abs(v_hi) ? Position{n_lo, lo, width} : Position{n_hi, hi, width};
}

// Appended to the note of an event whose bracket could not be narrowed to the tolerance
// (the corrector fails near it: G^k is singular there, or a branch point makes the
// corrector's matrix singular); `bracket` says how far it got.
constexpr const char* unlocated_note = " (bracket not narrowed: the corrector fails near it)";

std::string bound_note(const System& sys, bool upper)
{
    return sys.path.name + (upper ? " = max" : " = min");
}

std::string boundary_note(TestKind k)
{
    switch (k) {
        case TestKind::xi_zero: return "xi -> 0";
        case TestKind::xi_one: return "xi -> 1";
        case TestKind::wall_down: return "p -> 0: the wall no longer sends the ball down into the corner";
        default: return "U -> 0";
    }
}

// Classifies the located zero of a non-terminal test; nullopt when it is no event (a
// neutral saddle, mu_i mu_j = 1 for a real pair).
// Checks the located zero of a non-terminal test against the eigenvalues there and names
// the event; nullopt when the eigenvalues do not confirm it (the test function changed sign
// through a pole, where G^k is singular, or at a neutral saddle, mu_i mu_j = 1 for a real
// pair).
std::optional<std::pair<BranchEvent, std::string>> classify_event(const Test& test, const Node& n)
{
    const TestKind kind = test.kind;
    if (kind == TestKind::wall_grip || kind == TestKind::floor_grip) {
        return std::pair{BranchEvent::grip_slide, std::string(kind == TestKind::wall_grip ? "wall" : "floor") +
                                                      " impact after point " + std::to_string(test.point) +
                                                      " of the cycle: psi = psi*, grips on one side, slides on the other"};
    }
    const auto ev = sorted_eigenvalues(n.ev.g.dG);
    if (!ev) return std::nullopt;
    const auto has_eigenvalue = [&](double mu) {
        return std::any_of(ev->begin(), ev->end(),
                           [&](const std::complex<double>& z) { return std::abs(z - mu) <= confirmation_tolerance; });
    };
    switch (kind) {
        case TestKind::fold:
            if (!has_eigenvalue(1.0)) return std::nullopt;
            return std::pair{BranchEvent::fold, std::string()};
        case TestKind::branch:
            if (!has_eigenvalue(1.0)) return std::nullopt;
            return std::pair{BranchEvent::branch_point, std::string()};
        case TestKind::kappa:
            return std::pair{BranchEvent::branch_point, std::string("kappa = 1: an interior branch meets the plane")};
        case TestKind::period_doubling:
            if (!has_eigenvalue(-1.0)) return std::nullopt;
            return std::pair{BranchEvent::period_doubling, std::string()};
        case TestKind::neimark_sacker: {
            for (const auto& z : *ev) {
                if (z.imag() > confirmation_tolerance && std::abs(std::abs(z) - 1.0) <= confirmation_tolerance) {
                    const double angle = std::arg(z);
                    return std::pair{BranchEvent::neimark_sacker,
                                     "angle " + format_double(angle) + " rad (" + format_double(angle / (2.0 * std::numbers::pi)) +
                                         " turns)"};
                }
            }
            return std::nullopt;
        }
        default: break;
    }
    return std::nullopt;
}

// SPEC.md 1b: where an impact of the cycle passes from gripping to sliding, G^k is
// continuous but its Jacobian jumps, and so does the branch's tangent. A turn beyond the
// step guard's (a gripping cycle does not depend on mu: its branch runs straight along mu,
// and turns at the switch toward the sliding cycles') is refused at every step size. The
// step's end b is on the far side when a grip test changes sign between a and b: the
// switching point between them, located, is where the branch goes on, along b's tangent.
// nullopt when no grip test changes sign or the location finds no zero.
std::optional<Position> switching_point(const Context& c, const Node& a, double h, const std::vector<double>& va,
                                        const Node& b, const std::vector<double>& vb)
{
    for (std::size_t j = 0; j < c.tests.size(); ++j) {
        const TestKind kind = c.tests[j].kind;
        if (kind != TestKind::wall_grip && kind != TestKind::floor_grip) continue;
        if (significant_sign(c.tests[j], va[j]) * significant_sign(c.tests[j], vb[j]) >= 0) continue;
        Position where = locate(c, j, a, h, va[j], b, vb[j]);
        if (std::abs(test_value(c.sys, c.tests[j], where.node, c.set)) > switch_tolerance) continue;
        where.node.t = b.t;
        return where;
    }
    return std::nullopt;
}

struct Direction {
    std::vector<Node> nodes;        // nodes[0] is the start
    std::vector<double> arclength;  // of each node, from the start
    std::vector<Located> events;
    BranchEvent end = BranchEvent::none;  // how it stopped
    std::string end_note;
    bool closed = false;  // came back to the start
};

// Where the branch leaves the region or the parameter range on the step a -> b (node ia to
// the next): the first such crossing.
std::optional<Located> first_exit(const Context& c, const Node& a, const Node& b, double h, const std::vector<double>& va,
                                  const std::vector<double>& vb, std::size_t ia)
{
    std::optional<Located> stop;
    for (std::size_t j = 0; j < c.tests.size(); ++j) {
        if (!terminal(c.tests[j].kind) || !(va[j] > 0.0) || vb[j] > 0.0) continue;
        Position where = locate(c, j, a, h, va[j], b, vb[j]);
        if (stop && stop->h <= where.h) continue;
        const TestKind kind = c.tests[j].kind;
        const bool bound = kind == TestKind::lower_bound || kind == TestKind::upper_bound;
        Node n = std::move(where.node);
        double bracket = where.bracket;
        if (bound) {
            const double value = kind == TestKind::upper_bound ? c.set.max : c.set.min;
            if (auto exact = solve_at_parameter(c.sys, n.y, value, a.t)) {
                n = std::move(*exact);
                bracket = 0.0;
            }
        }
        stop = Located{std::move(n), ia, where.h, bound ? BranchEvent::end : BranchEvent::boundary,
                       bound ? bound_note(c.sys, kind == TestKind::upper_bound) : boundary_note(kind), bracket};
        if (bracket > location_tolerance * (1.0 + h)) stop->note += unlocated_note;
    }
    return stop;
}

// Sign changes of the other tests at b (the node after d's last, a step h on, with test
// values vb) since their last significant value; `last` (per test: that sign and its node)
// updated.
std::vector<Located> sign_changes(const Context& c, const Direction& d, const std::vector<std::vector<double>>& values,
                                  std::vector<std::pair<int, std::size_t>>& last, const Node& b, double h,
                                  const std::vector<double>& vb)
{
    const std::size_t ia = d.nodes.size() - 1;
    const std::vector<double>& va = values.back();
    std::vector<Located> found;
    for (std::size_t j = 0; j < c.tests.size(); ++j) {
        if (terminal(c.tests[j].kind)) continue;
        const int sb = significant_sign(c.tests[j], vb[j]);
        if (sb == 0) continue;
        const auto [sa, since] = last[j];
        last[j] = {sb, ia + 1};
        if (sa == 0 || sa == sb) continue;
        // The zero lies between node `since` and b; noise in between may hide which step
        // holds it: take the last step whose raw values differ in sign.
        std::size_t i = ia;
        double fa = va[j];
        while (i > since && (fa > 0.0) == (vb[j] > 0.0)) fa = values[--i][j];
        const Node& from = d.nodes[i];
        const Node& to = i == ia ? b : d.nodes[i + 1];
        const double step_h = (i == ia ? h : d.arclength[i + 1] - d.arclength[i]);
        const double f_to = i == ia ? vb[j] : values[i + 1][j];
        Position where = locate(c, j, from, step_h, fa, to, f_to);
        auto what = classify_event(c.tests[j], where.node);
        if (!what) continue;
        if (where.bracket > location_tolerance * (1.0 + step_h)) what->second += unlocated_note;
        found.push_back({std::move(where.node), i, where.h, what->first, std::move(what->second), where.bracket});
    }
    return found;
}

Direction trace(const Context& c, const Node& start)
{
    Direction d;
    d.nodes.push_back(start);
    d.arclength.push_back(0.0);
    std::vector<std::vector<double>> values{test_values(c.sys, c.tests, start, c.set)};
    // Per test: the last significant sign and the node where it was seen.
    std::vector<std::pair<int, std::size_t>> last(c.tests.size(), {0, 0});
    for (std::size_t j = 0; j < c.tests.size(); ++j) last[j] = {significant_sign(c.tests[j], values[0][j]), 0};

    double h = c.set.initial_step;
    while (true) {
        if (static_cast<int>(d.nodes.size()) > c.set.max_points) {
            d.end = BranchEvent::end;
            d.end_note = "point limit " + std::to_string(c.set.max_points) + " reached";
            return d;
        }
        const Node& a = d.nodes.back();
        auto b = step(c.sys, a, h);
        // Guards against jumping to another branch: the tangent turns little and the
        // corrector stays near the predictor.
        const bool ok = b && b->t.dot(a.t) >= min_tangent_cosine && (b->y - (a.y + h * a.t)).norm() <= h;
        std::optional<Position> kink;
        if (!ok && b) kink = switching_point(c, a, h, values.back(), *b, test_values(c.sys, c.tests, *b, c.set));
        // The step taken: to the switch, where it leaves along the far side's tangent.
        const double taken = kink ? kink->h : h;
        if (kink) {
            b = std::move(kink->node);
        } else if (!ok) {
            h *= 0.5;
            if (h < c.set.min_step) {
                d.end = BranchEvent::end;
                d.end_note = "the corrector fails at step sizes down to " + format_double(c.set.min_step);
                return d;
            }
            continue;
        }
        const std::vector<double> vb = test_values(c.sys, c.tests, *b, c.set);
        const std::vector<double>& va = values.back();
        const std::size_t ia = d.nodes.size() - 1;

        const std::optional<Located> stop = first_exit(c, a, *b, taken, va, vb, ia);
        std::vector<Located> found = sign_changes(c, d, values, last, *b, taken, vb);
        for (Located& e : found) {
            if (stop && e.after == stop->after && e.h >= stop->h) continue;
            d.events.push_back(std::move(e));
        }
        if (stop) {
            d.end = stop->event;
            d.end_note = stop->note;
            d.events.push_back(*stop);
            return d;
        }

        const double s = d.arclength.back() + taken;
        // Back at the start (a closed branch): stop, the loop is complete.
        const Vector4 to_start = d.nodes.front().y;
        const bool passed_start = d.nodes.size() > 3 && (to_start - a.y).dot(a.t) > 0.0 &&
                                  (to_start - b->y).dot(b->t) <= 0.0 && (to_start - b->y).norm() < taken;
        const int iterations = b->iterations;
        d.nodes.push_back(std::move(*b));
        d.arclength.push_back(s);
        values.push_back(vb);
        if (passed_start) {
            d.end = BranchEvent::end;
            d.end_note = "closed branch: back at the start";
            d.closed = true;
            return d;
        }
        if (iterations <= easy_iterations) h = std::min(h * growth, c.set.max_step);
    }
}

BranchPoint describe(const System& sys, const Node& n, double arclength)
{
    BranchPoint p;
    p.parameter = n.y(3);
    p.point = as_state(n.y.head<3>());
    p.arclength = arclength;
    p.lambda = n.ev.g.lambda;
    p.residual = (as_vector(n.ev.g.image) - n.y.head<3>()).cwiseAbs().maxCoeff();
    const auto& orbit = n.ev.g.orbit;
    const auto first = std::min_element(orbit.begin(), orbit.end(), lexicographically_less);
    p.representative = *first;
    Eigen::Matrix3d dG = n.ev.g.dG;
    if (first != orbit.begin()) {
        // D(G^k) at the representative, as fixed-points computes it (similar to dG).
        dG = parameter_jacobian(p.representative, sys.path, p.parameter, sys.period).dG;
    }
    if (const auto ev = sorted_eigenvalues(dG)) {
        p.eigenvalues = *ev;
        p.stability = classify(p.eigenvalues);
    } else {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        p.eigenvalues.fill({nan, nan});
        p.stability = Stability::marginal;
    }
    return p;
}

// The direction's points after the start, events in place.
std::vector<BranchPoint> points_of(const System& sys, const Direction& d, double sign)
{
    std::vector<BranchPoint> out;
    std::vector<const Located*> events;
    for (const Located& e : d.events) events.push_back(&e);
    std::stable_sort(events.begin(), events.end(), [](const Located* x, const Located* y) {
        return x->after != y->after ? x->after < y->after : x->h < y->h;
    });
    auto next = events.begin();
    for (std::size_t i = 0; i < d.nodes.size(); ++i) {
        if (i > 0) out.push_back(describe(sys, d.nodes[i], sign * d.arclength[i]));
        for (; next != events.end() && (*next)->after == i; ++next) {
            BranchPoint p = describe(sys, (*next)->node, sign * (d.arclength[i] + (*next)->h));
            p.event = (*next)->event;
            p.note = (*next)->note;
            p.bracket = (*next)->bracket;
            out.push_back(std::move(p));
        }
    }
    if (d.end == BranchEvent::end && (d.events.empty() || d.events.back().event != BranchEvent::end)) {
        // Stopped for a reason other than a located crossing: the last point says why.
        if (out.empty()) {
            BranchPoint p = describe(sys, d.nodes.back(), 0.0);
            out.push_back(std::move(p));
        }
        out.back().event = BranchEvent::end;
        out.back().note = d.end_note;
    }
    return out;
}

}  // namespace

std::string_view name(Parameter p)
{
    switch (p) {
        case Parameter::e: return "e";
        case Parameter::alpha: return "alpha";
        case Parameter::e_wall: return "e_wall";
        case Parameter::alpha_wall: return "alpha_wall";
        case Parameter::e_floor: return "e_floor";
        case Parameter::alpha_floor: return "alpha_floor";
        case Parameter::mu: return "mu";
        case Parameter::mu_wall: return "mu_wall";
        case Parameter::mu_floor: return "mu_floor";
        case Parameter::inertia: return "inertia";
    }
    return "unknown";
}

std::optional<Parameter> parameter_named(std::string_view text)
{
    for (const Parameter p : all_parameters) {
        if (name(p) == text) return p;
    }
    return std::nullopt;
}

double parameter_value(const Model& m, Parameter p)
{
    const Kind k = kind_of(p);
    if (k == Kind::inertia) return m.inertia;
    Surface s = sets_surface(p, true) ? m.wall : m.floor;  // e, alpha, mu: the wall's
    return coefficient(s, k);
}

Model with_parameter(Model m, Parameter p, double value)
{
    const Kind k = kind_of(p);
    if (k == Kind::inertia) {
        m.inertia = value;
        return m;
    }
    if (sets_surface(p, true)) coefficient(m.wall, k) = value;
    if (sets_surface(p, false)) coefficient(m.floor, k) = value;
    return m;
}

bool parameter_defined(const Model& m, Parameter p)
{
    if (p == Parameter::e) return m.wall.e == m.floor.e;
    if (p == Parameter::alpha) return m.wall.alpha == m.floor.alpha;
    if (p == Parameter::mu) return m.wall.mu == m.floor.mu;
    return true;
}

bool parameter_in_range(Parameter p, double value) { return coefficient_in_range(name(p), value); }

const char* parameter_range_text(Parameter p) { return coefficient_range_text(name(p)); }

Model ParameterPath::at(double s) const
{
    // An infinite mu stays infinite (its rate is 0 unless mu is the parameter).
    const auto surface = [s](const Surface& o, const Surface& d) {
        return Surface{o.e + s * d.e, o.alpha + s * d.alpha, d.mu == 0.0 ? o.mu : o.mu + s * d.mu};
    };
    return {surface(origin.wall, direction.wall), surface(origin.floor, direction.floor),
            origin.inertia + s * direction.inertia};
}

ParameterPath ParameterPath::along(const Model& model, Parameter p)
{
    ParameterPath path{with_parameter(model, p, 0.0), with_parameter(no_change, p, 1.0),
                       std::string(superball::name(p))};
    return path;
}

ParameterJacobian parameter_jacobian(const CanonicalState<double>& s, const Model& model, Parameter p, int k)
{
    return parameter_jacobian(s, ParameterPath::along(model, p), parameter_value(model, p), k);
}

ParameterJacobian parameter_jacobian(const CanonicalState<double>& s, const ParameterPath& path, double value, int k)
{
    const BasicModelMatrices<Dual4> m = dual_matrices(path, value);
    CanonicalState<Dual4> c{Dual4(s.xi, 4, 0), Dual4(s.U, 4, 1), Dual4(s.W, 4, 2)};
    Dual4 lambda(1.0);
    ParameterJacobian r;
    r.orbit.reserve(static_cast<std::size_t>(std::max(k, 0)));
    for (int i = 0; i < k; ++i) {
        r.orbit.push_back(value_of(c));
        const CanonicalStep<Dual4> g = canonical_map(c, m);
        lambda = lambda * g.lambda;
        c = g.next;
    }
    r.image = value_of(c);
    r.lambda = lambda.value();
    const Dual4* rows[3] = {&c.xi, &c.U, &c.W};
    for (int i = 0; i < 3; ++i) {
        r.dG.row(i) = rows[i]->derivatives().head<3>().transpose();
        r.dG_dp(i) = rows[i]->derivatives()(3);
    }
    r.finite = std::isfinite(r.lambda) && r.lambda > 0.0 && as_vector(r.image).allFinite() && r.dG.allFinite() &&
               r.dG_dp.allFinite();
    return r;
}

std::string_view name(BranchEvent e)
{
    switch (e) {
        case BranchEvent::none: return "";
        case BranchEvent::fold: return "fold";
        case BranchEvent::period_doubling: return "period_doubling";
        case BranchEvent::neimark_sacker: return "neimark_sacker";
        case BranchEvent::branch_point: return "branch_point";
        case BranchEvent::boundary: return "boundary";
        case BranchEvent::end: return "end";
        case BranchEvent::grip_slide: return "grip_slide";
    }
    return "unknown";
}

std::optional<Branch> continue_cycle(const Cycle& start, const Model& model, Parameter parameter,
                                     const ContinuationSettings& settings)
{
    return continue_cycle(start, ParameterPath::along(model, parameter), parameter_value(model, parameter), settings);
}

std::optional<Branch> continue_cycle(const Cycle& start, const ParameterPath& path, double p0,
                                     const ContinuationSettings& settings)
{
    if (start.points.empty() || start.period < 1) return std::nullopt;
    const System sys{path, start.period, start.corner};
    Vector4 y0;
    y0 << as_vector(start.points.front()), p0;
    // The start solved in the branch's own variables (plain coordinates) at its parameter.
    auto first = evaluate(sys, y0);
    if (!first) return std::nullopt;
    // Initial tangent: the null vector of [H_x H_p]; forward is increasing p.
    Vector4 t = null_vector(first->J);
    if (sys.corner) t(0) = 0.0;
    if (!(t.norm() > 0.0) || !t.allFinite()) return std::nullopt;
    t.normalize();
    if (std::abs(t(3)) > significance) {
        if (t(3) < 0.0) t = -t;
    } else {
        // p constant along the branch (at a fold, or a family at fixed p): the largest
        // component positive.
        Eigen::Index i = 0;
        t.cwiseAbs().maxCoeff(&i);
        if (t(i) < 0.0) t = -t;
    }
    auto refined = solve_at_parameter(sys, y0, p0, t);
    if (!refined) return std::nullopt;
    // solve_at_parameter oriented the tangent along t.
    const Node start_node = *refined;

    const std::vector<Test> tests = tests_of(sys);
    const Context c{sys, settings, tests};
    const Direction forward = trace(c, start_node);
    Branch b;
    b.period = start.period;
    b.domain = start.corner ? Domain::corner : Domain::interior;
    std::vector<BranchPoint> back;
    if (!forward.closed) {
        Node reversed = start_node;
        reversed.t = -reversed.t;
        back = points_of(sys, trace(c, reversed), -1.0);
    }
    std::reverse(back.begin(), back.end());
    b.points = std::move(back);
    b.start = b.points.size();
    b.points.push_back(describe(sys, start_node, 0.0));
    for (BranchPoint& p : points_of(sys, forward, 1.0)) b.points.push_back(std::move(p));
    return b;
}

}  // namespace superball
