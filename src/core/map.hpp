// The floor -> wall -> floor map: physical (F) and canonical (G), SPEC.md sections 1-2.
//
// Each map is written once, as a template on the number type T (double, or a SIMD
// batch of doubles in the vectorised kernel) so both instantiations evaluate the same
// operations in the same order.
#pragma once

#include <cmath>
#include <limits>

#include "impact.hpp"
#include "state.hpp"

namespace superball {

namespace detail {
// sqrt that finds the SIMD (or automatic-differentiation) overload by argument-dependent
// lookup. `auto`: for expression-template number types sqrt returns another type.
using std::sqrt;
template <class T>
auto root(const T& x)
{
    return sqrt(x);
}
}  // namespace detail

// Flight from the floor to the wall (seed eqs. 1 and 4).
template <class T>
struct WallArrival {
    T t;    // flight time -x/u
    T y;    // height of the centre at the wall; <= 0: the ball lands first (missed)
    T v_w;  // vertical velocity at the wall
};

template <class T>
constexpr WallArrival<T> flight_to_wall(const PhysicalState<T>& s, double g)
{
    const T r = s.x / s.u;  // = -t
    return {-r, -r * (s.v + g * s.x / (2.0 * s.u)), s.v + g * r};
}

// Flight from height y back to the floor after the wall impact.
template <class T>
struct FloorArrival {
    T t;    // flight time T = (v+ - v_f)/g
    T x;    // x_{n+1} = u+ T
    T v_f;  // vertical velocity on arrival, -sqrt(v+^2 + 2 g y)
};

//
// T = (v+ - v_f)/g = (v+ + s)/g with s = sqrt(v+^2 + 2 g y). When the ball comes off the
// wall going down (v+ < 0) from low down (small y), v+ + s cancels: the same quantity is
// then computed as 2 y / (s - v+), which has no cancellation for v+ < 0. Near the plane
// xi -> 0 this keeps x_{n+1} (hence xi') accurate to rounding instead of losing digits.
template <class T>
constexpr FloorArrival<T> flight_to_floor(const Velocities<T>& after_wall, const T& y, double g)
{
    const T s = detail::root(after_wall.v * after_wall.v + 2.0 * g * y);
    // T(...): both branches of the same type even when T's arithmetic yields expression types.
    const T t = detail::choose(after_wall.v >= 0.0, T((after_wall.v + s) / g), T(2.0 * y / (s - after_wall.v)));
    return {t, after_wall.u * t, -s};
}

// Everything an excursion produces; the physical map F is its `next` state.
template <class T>
struct Excursion {
    WallArrival<T> to_wall;
    Velocities<T> after_wall;
    FloorArrival<T> to_floor;
    PhysicalState<T> next;  // state just after the floor bounce
};

// One excursion n -> n+1 in physical variables. Valid when the wall is reached
// (to_wall.y > 0); the caller decides what a miss means.
// `law`: ImpactLaw::walton everywhere but in the counting kernels' fast path (impact.hpp).
template <ImpactLaw law = ImpactLaw::walton, class T>
constexpr Excursion<T> excursion(const PhysicalState<T>& s, const ModelMatrices& m, double g)
{
    const WallArrival<T> w = flight_to_wall(s, g);
    const Velocities<T> after_wall = impact_at_wall<law>(Velocities<T>{s.u, w.v_w, s.W}, m.wall);
    const FloorArrival<T> f = flight_to_floor(after_wall, w.y, g);
    const Velocities<T> after_floor = impact_at_floor<law>(Velocities<T>{after_wall.u, f.v_f, after_wall.W}, m.floor);
    return {w, after_wall, f, {f.x, after_floor.u, after_floor.v, after_floor.W}};
}

// F: the physical map.
template <class T>
constexpr PhysicalState<T> physical_map(const PhysicalState<T>& s, const ModelMatrices& m, double g)
{
    return excursion(s, m, g).next;
}

// Result of G: the new canonical state and the multiplier lambda = v_{n+1}/v_n.
template <class T>
struct CanonicalStep {
    CanonicalState<T> next;
    T lambda;
};

// G: the physical map applied to the representative with v = 1, g = 1, then divided by
// the new scale. For that representative x = 2 xi |U|, so the flight to the wall takes
// t = 2 xi, reaches height y = 2 xi (1 - xi) and arrives with v_w = 1 - 2 xi; writing
// these closed forms (rather than going through x) avoids the rounding of x/u, and the
// flight back is computed without cancellation (flight_to_floor), so G keeps full
// relative precision near the boundary planes xi -> 0 and xi -> 1. Valid for xi < 1;
// xi' is meaningful when U' < 0.
// S: the coefficients' number type (double; in continuation, a differentiated parameter).
// law: which impacts (impact.hpp); walton but in the counting kernels' path for a model
// without friction.
template <ImpactLaw law = ImpactLaw::walton, class T, class S>
constexpr CanonicalStep<T> canonical_map(const CanonicalState<T>& c, const BasicModelMatrices<S>& m)
{
    const T t_wall = 2.0 * c.xi;
    const T y = t_wall * (1.0 - c.xi);
    const Velocities<T> after_wall = impact_at_wall<law>(Velocities<T>{c.U, 1.0 - t_wall, c.W}, m.wall);
    const FloorArrival<T> f = flight_to_floor(after_wall, y, 1.0);
    const Velocities<T> after_floor = impact_at_floor<law>(Velocities<T>{after_wall.u, f.v_f, after_wall.W}, m.floor);
    const T lambda = after_floor.v;
    const T U = after_floor.u / lambda;
    // xi' = g x' / (2 |u'| v') with g = 1; |u'| = -u' on the branch where it matters.
    return {{f.x / (-2.0 * after_floor.u * lambda), U, after_floor.W / lambda}, lambda};
}

// What decides whether each impact of G's excursion from c slides (SPEC.md 1b): the contact
// velocity s and the approach speed v_n at the wall and at the floor, for the representative
// v = 1, g = 1 (psi = |s| / v_n is the same for every representative).
struct ImpactContacts {
    double s_wall, approach_wall, s_floor, approach_floor;
};

// canonical_map's first half written again: shared through a struct of the three states (wall,
// after the wall, floor arrival), the AVX2 kernel ran at 0.64 of its speed (its loops spilled
// the batches; bench_kernel BM_count_slice/avx2/4096, 5 interleaved repetitions).
inline ImpactContacts impact_contacts(const CanonicalState<double>& c, const ModelMatrices& m)
{
    const double v_w = 1.0 - 2.0 * c.xi;
    const Velocities<double> after_wall = walton_wall_impact(Velocities<double>{c.U, v_w, c.W}, m.wall);
    const FloorArrival<double> f = flight_to_floor(after_wall, 2.0 * c.xi * (1.0 - c.xi), 1.0);
    return {v_w - c.W, -c.U, after_wall.u + after_wall.W, -f.v_f};
}

// Whether a step of G stayed within double precision: the multiplier is positive and
// finite, U' and W' are finite, and xi' is a number where it is used (U' < 0). It fails
// only for starts far outside any physical scale (|U| or |W| beyond about 1e150, where
// v+^2 overflows, or a subnormal e, where lambda underflows); the counting kernels then
// report the start invalid instead of reading an overflowed state as a miss or a leave.
// A mask for SIMD batches. (Sane starts never fail it: tests/core/test_edges.cpp.)
template <class T>
auto representable(const CanonicalStep<T>& s)
{
    using std::abs;
    constexpr double inf = std::numeric_limits<double>::infinity();
    return s.lambda > 0.0 && s.lambda < inf && abs(s.next.U) < inf && abs(s.next.W) < inf &&
           (s.next.U >= 0.0 || s.next.xi == s.next.xi);
}

}  // namespace superball
