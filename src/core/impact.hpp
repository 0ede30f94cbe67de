// The two impacts of an excursion (SPEC.md sections 1 and 1b, seed eqs. 2, 6, 7).
//
// Both impacts reverse the normal velocity and scale it by e. Tangentially, the velocity
// s of the centre and the spin W = a*omega change so that the angular momentum about the
// contact point (kappa W + v at the wall, kappa W - u at the floor) is conserved, and the
// contact point's tangential velocity is reversed and scaled by a factor beta:
//   * an impact that grips: beta = alpha (the Cross model), a linear map of (s, W), the
//     "impact matrix" below;
//   * an impact that slides (Walton's law, a finite mu): the tangential impulse is mu
//     times the normal one, so the centre's tangential velocity changes by
//     mu (1 + e) v_n against the contact velocity, and beta = -1 + mu (1 + e) (1 + 1/kappa) / psi
//     with psi = |contact velocity| / v_n. It slides when that beta is below alpha.
// Only the sign with which W enters the contact velocity differs between the wall
// (contact velocity v - W) and the floor (contact velocity u + W).
//
// The functions are templates on the number type so that the scalar code and the
// SIMD kernel are one piece of code, giving bit-identical results.
#pragma once

#include <cmath>
#include <experimental/simd>

#include "model.hpp"

namespace superball {

namespace detail {
// cond ? a : b, lane by lane for SIMD batches. Both branches are computed.
inline double choose(bool cond, double a, double b) { return cond ? a : b; }
// Other scalar number types (automatic differentiation in dynamics.hpp).
template <class T>
T choose(bool cond, const T& a, const T& b)
{
    return cond ? a : b;
}
template <class T, class Abi>
std::experimental::simd<T, Abi> choose(const typename std::experimental::simd<T, Abi>::mask_type& cond,
                                       std::experimental::simd<T, Abi> a, const std::experimental::simd<T, Abi>& b)
{
    std::experimental::where(!cond, a) = b;
    return a;
}
// |x| found by argument-dependent lookup (SIMD batches, automatic differentiation).
using std::abs;
template <class T>
T magnitude(const T& x)
{
    return T(abs(x));
}
}  // namespace detail

// The coefficients of one surface's impact, computed once per model: the kernel then does
// two multiplications and one addition per matrix entry, in the same order in every
// instantiation. S is the number type of the coefficients: double everywhere but in
// continuation (core/continuation.hpp), where a coefficient is the parameter and carries
// its derivative (automatic differentiation).
//
// With q = 1/kappa the matrix of a gripping impact is ((q - alpha), (1 + alpha);
// q (1 + alpha), (1 - q alpha)) / (q + 1). For the solid ball (kappa = 2/5, q = 2.5 exactly)
// each numerator and the denominator are those of section 1 ((5 - 2 alpha)/7, ...) halved,
// and halving is exact in binary floating point: the entries are the same doubles.
template <class S = double>
struct BasicImpactMatrix {
    S e;       // normal restitution
    S c_ss;    // (q - alpha)/(q + 1), (5 - 2 alpha)/7 for the solid ball: tangential velocity kept
    S c_sW;    // (1 + alpha)/(q + 1), (2/7)(1 + alpha): spin fed into the tangential velocity
    S c_Ws;    // q (1 + alpha)/(q + 1), (5/7)(1 + alpha): tangential velocity fed into the spin
    S c_WW;    // (1 - q alpha)/(q + 1), (2 - 5 alpha)/7: spin kept
    // Walton's law (used by the impacts of ImpactLaw::walton only):
    S q;           // 1/kappa: the spin's change per unit change of the centre's tangential velocity
    S slide;       // mu (1 + e): a sliding impact's change of tangential velocity per unit of v_n
    S grip_ratio;  // mu (1 + e)(1 + q)/(1 + alpha): the largest psi = |s|/v_n that grips

    // Not declared constexpr: a defaulted comparison is constexpr where S allows it, and
    // declaring it so is an error for the S that do not (clang).
    friend bool operator==(const BasicImpactMatrix&, const BasicImpactMatrix&) = default;

    static constexpr BasicImpactMatrix of(const S& e, const S& alpha, const S& kappa, const S& mu)
    {
        const S q = 1.0 / kappa;
        const S slide = mu * (1.0 + e);
        return {e,     (q - alpha) / (q + 1.0), (1.0 + alpha) / (q + 1.0), q * (1.0 + alpha) / (q + 1.0),
                (1.0 - q * alpha) / (q + 1.0), q, slide, slide * (1.0 + q) / (1.0 + alpha)};
    }
    static constexpr BasicImpactMatrix of(Surface s, double kappa = solid_ball_inertia)
    {
        return of(S(s.e), S(s.alpha), S(kappa), S(s.mu));
    }
};

using ImpactMatrix = BasicImpactMatrix<double>;

template <class S = double>
struct BasicModelMatrices {
    BasicImpactMatrix<S> wall;
    BasicImpactMatrix<S> floor;
    // Some impact may slide (Model::frictional): the kernels take ImpactLaw::walton.
    bool frictional = false;

    friend bool operator==(const BasicModelMatrices&, const BasicModelMatrices&) = default;  // constexpr where S allows

    static constexpr BasicModelMatrices of(const Model& m)
    {
        return {BasicImpactMatrix<S>::of(m.wall, m.inertia), BasicImpactMatrix<S>::of(m.floor, m.inertia),
                m.frictional()};
    }
};

using ModelMatrices = BasicModelMatrices<double>;

// Which impacts a map applies: `cross` grips always (exactly the Cross model; the counting
// kernels' fast path when no mu is finite), `walton` slides where the friction limit says
// so (with every mu infinite it grips always too, and gives the same bits).
enum class ImpactLaw : unsigned char { cross, walton };

template <class T>
struct Velocities {
    T u;  // horizontal velocity of the centre
    T v;  // vertical velocity of the centre
    T W;  // a * omega
};

// Wall impact (x = 0) that grips: u is normal, v tangential.
//   u+ = -e_wall u
//   v+ = (2/7)(1+alpha_wall) W + (1/7)(5-2 alpha_wall) v_w      (kappa = 2/5)
//   W+ = (5/7)(1+alpha_wall) v_w + (1/7)(2-5 alpha_wall) W
template <class T, class S>
constexpr Velocities<T> wall_impact(const Velocities<T>& in, const BasicImpactMatrix<S>& wall)
{
    return {-wall.e * in.u, wall.c_sW * in.W + wall.c_ss * in.v, wall.c_Ws * in.v + wall.c_WW * in.W};
}

// Floor impact (y = 0) that grips: v is normal, u tangential.
//   u_{n+1} = (1/7)(5-2 alpha_floor) u+ - (2/7)(1+alpha_floor) W+    (kappa = 2/5)
//   W_{n+1} = -(5/7)(1+alpha_floor) u+ + (1/7)(2-5 alpha_floor) W+
//   v_{n+1} = -e_floor v_f
template <class T, class S>
constexpr Velocities<T> floor_impact(const Velocities<T>& in, const BasicImpactMatrix<S>& floor)
{
    return {floor.c_ss * in.u - floor.c_sW * in.W, -floor.e * in.v, floor.c_WW * in.W - floor.c_Ws * in.u};
}

// Whether an impact with contact velocity s and approach speed v_n > 0 slides: psi = |s|/v_n
// beyond the grip ratio. Written as `>` so that an infinite mu (and 0/0) never slides, and
// with |v_n| so that it does not either where continuation evaluates G's analytic extension
// beyond the plane U = 0 (v_n = -U < 0 at the wall: no impact, inf * v_n = -inf).
template <class T, class S>
auto slides(const T& s, const T& approach, const BasicImpactMatrix<S>& m)
{
    return detail::magnitude(s) > m.grip_ratio * detail::magnitude(approach);
}

// The centre's change of tangential velocity in a sliding impact, signed as the contact
// velocity s: mu (1 + e) v_n.
template <class T, class S>
T sliding_change(const T& s, const T& approach, const BasicImpactMatrix<S>& m)
{
    const T change = m.slide * approach;
    return detail::choose(s >= 0.0, change, T(-change));
}

// Wall impact by Walton's law: the gripping impact where it grips; where it slides the
// tangential impulse mu (1 + e) m v_n opposes the contact velocity s = v - W, and
// kappa W + v is conserved (v+ = v - d, W+ = W + d/kappa).
template <class T, class S>
Velocities<T> walton_wall_impact(const Velocities<T>& in, const BasicImpactMatrix<S>& wall)
{
    const Velocities<T> grip = wall_impact(in, wall);
    const T s = in.v - in.W;
    const T approach = -in.u;
    const auto slid = slides(s, approach, wall);
    const T d = sliding_change(s, approach, wall);
    return {grip.u, detail::choose(slid, T(in.v - d), grip.v), detail::choose(slid, T(in.W + wall.q * d), grip.W)};
}

// Floor impact by Walton's law: contact velocity s = u + W, kappa W - u conserved
// (u' = u - d, W' = W - d/kappa where it slides).
template <class T, class S>
Velocities<T> walton_floor_impact(const Velocities<T>& in, const BasicImpactMatrix<S>& floor)
{
    const Velocities<T> grip = floor_impact(in, floor);
    const T s = in.u + in.W;
    const T approach = -in.v;
    const auto slid = slides(s, approach, floor);
    const T d = sliding_change(s, approach, floor);
    return {detail::choose(slid, T(in.u - d), grip.u), grip.v, detail::choose(slid, T(in.W - floor.q * d), grip.W)};
}

template <ImpactLaw law, class T, class S>
Velocities<T> impact_at_wall(const Velocities<T>& in, const BasicImpactMatrix<S>& wall)
{
    if constexpr (law == ImpactLaw::cross) return wall_impact(in, wall);
    else return walton_wall_impact(in, wall);
}

template <ImpactLaw law, class T, class S>
Velocities<T> impact_at_floor(const Velocities<T>& in, const BasicImpactMatrix<S>& floor)
{
    if constexpr (law == ImpactLaw::cross) return floor_impact(in, floor);
    else return walton_floor_impact(in, floor);
}

// What an impact did (trajectories, SPEC.md 1b): whether it slid, and its tangential factor
// beta = -s'/s: alpha where it gripped, -1 + mu (1 + e)(1 + 1/kappa) v_n/|s| in [-1, alpha)
// where it slid.
struct Contact {
    bool slid = false;
    double beta = 0.0;
};

inline Contact contact(double s, double approach, double alpha, const ImpactMatrix& m)
{
    if (!slides(s, approach, m)) return {false, alpha};
    return {true, -1.0 + m.slide * (1.0 + m.q) * approach / std::abs(s)};
}

}  // namespace superball
