// Linearisation, fixed points and cycles of the canonical map G (SPEC.md section 2).
//
// The Jacobians come from forward-mode automatic differentiation of the very template
// `canonical_map<T>` the counting kernels run (T = Eigen::AutoDiffScalar), so they are
// the derivatives of the code, not of a second copy of the formulas.
//
// A period-k cycle of G is a self-similar motion: after k excursions the launch is the
// same up to the scale, which has shrunk by the product of the multipliers lambda.
#pragma once

#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstdint>
#include <optional>
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

inline Eigen::Vector3d as_vector(const CanonicalState<double>& c) { return {c.xi, c.U, c.W}; }
inline CanonicalState<double> as_state(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }

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
    // s and every iterate up to G^k(s) lie in the region of in_region(): G is the motion
    // along the whole way (otherwise the ball missed the wall or left on the way).
    bool in_region = false;
};

IterateJacobian iterate_jacobian(const CanonicalState<double>& s, const ModelMatrices& m, int k);

// G^k(s) without derivatives; nullopt if some iterate leaves the region.
std::optional<CanonicalState<double>> iterate(const CanonicalState<double>& s, const ModelMatrices& m, int k);

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

// Newton's method stops when |G^k(s) - s| <= newton_tolerance |s|; a cycle is reported
// only if |G^k(s) - s| <= residual_tolerance |s|.
inline constexpr double newton_tolerance = 1e-12;
inline constexpr double residual_tolerance = 1e-10;

// Stability of a cycle from the eigenvalues of the Jacobian of G^k.
Stability classify(std::span<const std::complex<double>> eigenvalues);

struct Cycle {
    int period = 0;                             // minimal period k
    std::vector<CanonicalState<double>> points;  // points[0]: smallest xi; then G(points[i]) = points[i+1]
    double lambda = 0.0;                         // product of the multipliers over the cycle
    std::array<std::complex<double>, 3> eigenvalues{};  // of D(G^k) at points[0], by decreasing modulus
    Stability stability = Stability::marginal;
    double residual = 0.0;  // |G^k(points[0]) - points[0]| / |points[0]|
    // D(G^k) has an eigenvalue 1 (within 1e-7): the cycle is not isolated but a member of
    // a continuous family, such as the self-retracing motions of the elastic ball.
    bool family = false;
};

// Damped Newton iteration for G^k(s) = s from `start`: the step solves the linearised
// equation (minimum-norm least squares, so it also converges onto families of cycles),
// then is halved until every iterate of G^k stays in the region and |G^k(s) - s|
// decreases. Returns the converged point, or nullopt when the iteration fails.
std::optional<CanonicalState<double>> newton_cycle(const CanonicalState<double>& start, const ModelMatrices& m, int k);

// The cycle through `point`, which satisfies G^k(point) ~ point: its minimal period
// (a divisor of k), points, multiplier, eigenvalues and stability. nullopt unless the
// whole cycle lies in the region and the residual is within residual_tolerance.
std::optional<Cycle> make_cycle(const CanonicalState<double>& point, const ModelMatrices& m, int k);

// Same cycle: same period and the representative of one is a point of the other.
bool same_cycle(const Cycle& a, const Cycle& b);

// Removes repeated cycles (keeping the first found) and sorts by period, then xi, U, W of
// the representative.
std::vector<Cycle> distinct_cycles(std::span<const Cycle> cycles);

// Reproducible Newton starts in the region, drawn from std::mt19937_64 seeded with `seed`:
// xi uniform in (0, 1), U = -10^r with r uniform in (-2, 2), W uniform in
// [-3 max(1, |U|), 3 max(1, |U|)]. Start i is the same for every count > i, so a parallel
// run that hands out the indices of one list finds what a serial run finds.
std::vector<CanonicalState<double>> seeded_starts(std::uint64_t seed, std::uint64_t count);

// Serial search: every start, every period up to max_period, deduplicated.
std::vector<Cycle> find_cycles(const ModelMatrices& m, int max_period, std::uint64_t starts, std::uint64_t seed);

}  // namespace superball
