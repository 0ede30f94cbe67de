// Linearisation, fixed points and cycles of the canonical map G (SPEC.md section 2).
//
// The Jacobians come from forward-mode automatic differentiation of the very template
// `canonical_map<T>` the counting kernels run (T = Eigen::AutoDiffScalar), so they are
// the derivatives of the code, not of a second copy of the formulas.
//
// A period-k cycle of G is a self-similar motion: after k excursions the launch is the
// same up to the scale, which has shrunk by the product of the multipliers lambda.
//
// Known answers (tests/core/test_dynamics.cpp), for e = alpha = 1 on both surfaces:
// * |det D(G)| = |U| / (|U'| lambda^6) everywhere: F preserves the flux measure
//   v dx du dv dW of the floor section, which is 2 |U| v^5 dxi dU dW dv in canonical
//   variables. On a cycle lambda = 1 (energy is conserved) and |det D(G^k)| = 1.
// * The self-retracing motions (xi, U, W) = ((1 + U)/2, U, 5U/2), -1 < U < 0, are fixed
//   points with lambda = 1: the ball meets the wall with W = -5/2 v_w, which the rough
//   elastic wall reverses exactly (no angular momentum about the contact point), retraces
//   its path and is reversed again by the floor (W = 5/2 u). There det D(G) = 1, the
//   eigenvalue 1 belongs to the tangent of the family, and the other two satisfy
//   49 U mu^2 + (122 U + 40) mu + 49 U = 0: on the unit circle for U < -2/11 (marginal),
//   real mu, 1/mu for U > -2/11 (saddle).
//
// Cycles on the corner plane. Where the wall sends the ball down (p < 0 in
// boundary_planes.md), G extends continuously to xi = 0 and maps that part of the plane
// into itself: canonical_map evaluated at xi = 0 is the plane map, and its automatic
// derivative d xi'/d xi there is the transverse multiplier kappa. A cycle on the plane is
// the limit of motions that go into the corner (the wall is hit at floor level every
// time). Its Jacobian is block triangular, so its eigenvalues are kappa (product over
// the cycle: < 1 means nearby launches approach the corner, infinitely many bounces) and
// those of the 2-D plane map. The search looks for them on request (Domain::corner).
#pragma once

#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstdint>
#include <optional>
#include <random>
#include <span>
#include <string_view>
#include <vector>

#include "map.hpp"

namespace superball {

// Where G is the motion: the ball reaches the wall (0 < xi < 1) and heads for it (U < 0).
inline bool in_region(const CanonicalState<double>& c)
{
    return std::isfinite(c.xi) && std::isfinite(c.U) && std::isfinite(c.W) && c.xi > 0.0 && c.xi < 1.0 && c.U < 0.0;
}

// Where cycles are looked for: the region of in_region(), or the corner plane xi = 0.
enum class Domain : std::uint8_t { interior, corner };

inline bool in_domain(const CanonicalState<double>& c, Domain d)
{
    if (d == Domain::interior) return in_region(c);
    return c.xi == 0.0 && std::isfinite(c.U) && std::isfinite(c.W) && c.U < 0.0;
}

inline Eigen::Vector3d as_vector(const CanonicalState<double>& c) { return {c.xi, c.U, c.W}; }
inline CanonicalState<double> as_state(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }
// The order that picks a cycle's representative (fixed-points, continuation): by xi, then U, then W.
bool lexicographically_less(const CanonicalState<double>& a, const CanonicalState<double>& b);

// G, lambda and their derivatives with respect to (xi, U, W) at one state.
struct StepJacobian {
    CanonicalStep<double> step;
    Eigen::Matrix3d dG;           // d(xi', U', W') / d(xi, U, W)
    Eigen::RowVector3d dlambda;   // d lambda / d(xi, U, W)
};

StepJacobian step_jacobian(const CanonicalState<double>& s, const ModelMatrices& m);

// G^k and the product of the k multipliers, with their derivatives (chain rule over the
// k steps).
struct IterateJacobian {
    CanonicalState<double> state;  // G^k(s)
    double lambda = 1.0;           // lambda(s_0) lambda(s_1) ... lambda(s_{k-1})
    Eigen::Matrix3d dG = Eigen::Matrix3d::Identity();
    Eigen::RowVector3d dlambda = Eigen::RowVector3d::Zero();
    // s and every iterate up to G^k(s) lie in the domain (by default the region of
    // in_region(): G is the motion along the whole way, the ball did not miss the wall or
    // leave on the way; on the corner plane: it stayed there).
    bool in_region = false;
};

IterateJacobian iterate_jacobian(const CanonicalState<double>& s, const ModelMatrices& m, int k,
                                 Domain domain = Domain::interior);

// G^k(s) without derivatives; nullopt if some iterate leaves the domain.
std::optional<CanonicalState<double>> iterate(const CanonicalState<double>& s, const ModelMatrices& m, int k,
                                              Domain domain = Domain::interior);

enum class Stability : std::uint8_t {
    stable,    // every eigenvalue of D(G^k) inside the unit circle
    unstable,  // every eigenvalue outside
    saddle,    // some inside, some outside
    marginal,  // none outside and not all inside, or none inside and not all outside:
               // some eigenvalue within marginal_tolerance of the unit circle decides
};

std::string_view name(Stability s);

// |eigenvalue| within this of 1 counts as on the unit circle.
inline constexpr double marginal_tolerance = 1e-9;

// Relative residual of G^k(s) = s: max(|xi' - xi| / xi, |(U', W') - (U, W)| / |(U, W)|)
// (xi' - xi in the form |log(xi'/xi)|). xi is compared relatively because G maps part of the
// plane xi = 0 into itself (boundary_planes.md): there xi' - xi -> 0 without xi' = xi.
// (On the corner plane itself only the (U, W) part counts.) Newton's method stops at newton_tolerance; a cycle is reported only within
// residual_tolerance.
inline constexpr double newton_tolerance = 1e-12;
inline constexpr double residual_tolerance = 1e-10;

// The eigenvalues of a Jacobian by decreasing modulus (ties: by real part, then imaginary
// part); nullopt if the eigensolver fails.
std::optional<std::array<std::complex<double>, 3>> sorted_eigenvalues(const Eigen::Matrix3d& a);

// Stability of a cycle from the eigenvalues of the Jacobian of G^k.
Stability classify(std::span<const std::complex<double>> eigenvalues);

struct Cycle {
    int period = 0;                             // minimal period k
    std::vector<CanonicalState<double>> points;  // points[0]: smallest xi; then G(points[i]) = points[i+1]
    double lambda = 0.0;                         // product of the multipliers over the cycle
    std::array<std::complex<double>, 3> eigenvalues{};  // of D(G^k) at points[0], by decreasing modulus
    Stability stability = Stability::marginal;
    double residual = 0.0;  // relative residual of G^k(points[0]) = points[0] (see above)
    // D(G^k) has an eigenvalue 1 (within 1e-6): the cycle is not isolated but a member of
    // a continuous family, such as the self-retracing motions of the elastic ball (or it
    // sits at a bifurcation).
    bool family = false;
    // On the corner plane xi = 0 (Domain::corner): every xi is 0, and the eigenvalue
    // D(G^k)(0, 0) is the transverse multiplier kappa.
    bool corner = false;
};

// Damped Newton iteration for G^k(s) = s from `start`, in the unknowns (log xi, U, W) with
// the Jacobian of iterate_jacobian: the step solves the linearised equation (minimum-norm
// least squares, so it also converges onto families of cycles), then is halved until
// every iterate of G^k stays in the region and the residual decreases. Returns the
// converged point, or nullopt when the iteration fails or leaves the region.
// On the corner plane the unknowns are (U, W), xi = 0 (the start's xi is ignored).
std::optional<CanonicalState<double>> newton_cycle(const CanonicalState<double>& start, const ModelMatrices& m, int k,
                                                   Domain domain = Domain::interior);

// The cycle through `point`, which satisfies G^k(point) ~ point: its minimal period
// (a divisor of k), points, multiplier, eigenvalues and stability. nullopt unless the
// whole cycle lies in the domain and the residual is within residual_tolerance.
std::optional<Cycle> make_cycle(const CanonicalState<double>& point, const ModelMatrices& m, int k,
                                Domain domain = Domain::interior);

// Same cycle: same period and domain, and the representative of one is a point of the other.
bool same_cycle(const Cycle& a, const Cycle& b);

// Removes repeated cycles (keeping the first found) and sorts: interior cycles first, then
// by period, then xi, U, W of the representative.
std::vector<Cycle> distinct_cycles(std::span<const Cycle> cycles);

// Reproducible Newton starts in the region, drawn in sequence from std::mt19937_64 seeded
// with `seed`: xi uniform in (0, 1), U = -10^r with r uniform in (-2, 2), W uniform in
// [-3 max(1, |U|), 3 max(1, |U|)]. A parallel run in which every rank draws the whole
// sequence and keeps its share of the indices uses the starts of the serial run.
class SeededStarts {
public:
    explicit SeededStarts(std::uint64_t seed) : rng_(seed) {}
    CanonicalState<double> next();

private:
    std::mt19937_64 rng_;
};

// The first `count` starts of SeededStarts(seed).
std::vector<CanonicalState<double>> seeded_starts(std::uint64_t seed, std::uint64_t count);

// Serial search: every start, every period up to max_period, deduplicated.
std::vector<Cycle> find_cycles(const ModelMatrices& m, int max_period, std::uint64_t starts, std::uint64_t seed,
                               Domain domain = Domain::interior);

}  // namespace superball
