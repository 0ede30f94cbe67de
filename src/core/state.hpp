// Launch states: physical (x, u, v, W) and canonical (xi, U, W), SPEC.md sections 1-2.
#pragma once

#include <cmath>

namespace superball {

// State just after a floor bounce: centre at (x, 0), velocity (u, v), W = a*omega.
// A launch toward the wall has x > 0, u < 0, v > 0.
template <class T = double>
struct PhysicalState {
    T x;
    T u;
    T v;
    T W;
};

// Canonical coordinates of a launch, the scale k of x -> k^2 x, (u, v, W) -> k (u, v, W)
// divided out:
//   xi = g x / (2 |u| v)   launch distance as a fraction of the free-flight range
//   U  = u / v             launch direction
//   W  = a omega / v       spin relative to the vertical speed
template <class T = double>
struct CanonicalState {
    T xi;
    T U;
    T W;
};

// Gravity and ball radius: needed only to go between physical and canonical variables.
struct Frame {
    double g = 9.81;
    double radius = 0.025;
};

inline bool is_launch(const PhysicalState<double>& s)
{
    return std::isfinite(s.x) && std::isfinite(s.u) && std::isfinite(s.v) && std::isfinite(s.W) && s.x > 0.0 &&
           s.u < 0.0 && s.v > 0.0;
}

// Admissible canonical launch (SPEC.md section 3, outcome invalid otherwise). xi >= 1 is
// admissible: it is a launch that misses the wall.
inline bool is_launch(const CanonicalState<double>& c)
{
    return std::isfinite(c.xi) && std::isfinite(c.U) && std::isfinite(c.W) && c.xi > 0.0 && c.U < 0.0;
}

// Physical -> canonical. Meaningful for launches (u < 0, v > 0).
inline CanonicalState<double> to_canonical(const PhysicalState<double>& s, double g)
{
    return {g * s.x / (2.0 * std::fabs(s.u) * s.v), s.u / s.v, s.W / s.v};
}

// The canonical coordinates of a physical start as count() needs them: those of the
// launch, or, for a state that is no launch toward the wall, a non-admissible canonical
// state (NaN) that count() reports as invalid.
inline CanonicalState<double> canonical_launch(const PhysicalState<double>& s, double g)
{
    if (!is_launch(s)) {
        const double nan = std::nan("");
        return {nan, nan, nan};
    }
    return to_canonical(s, g);
}

// Canonical -> the physical representative with vertical speed v (any v > 0 is the same
// launch up to scale).
inline PhysicalState<double> to_physical(const CanonicalState<double>& c, double g, double v)
{
    return {2.0 * c.xi * std::fabs(c.U) * v * v / g, c.U * v, v, c.W * v};
}

}  // namespace superball
