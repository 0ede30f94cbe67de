// The two impacts of an excursion (SPEC.md section 1, seed eqs. 2, 6, 7).
//
// Both impacts are the same linear map of the Cross/Garwin model: the normal
// velocity is reversed and scaled by e; the tangential velocity s of the centre
// and the spin W = a*omega mix so that the angular momentum about the contact
// point is conserved and the contact point's tangential velocity is reversed and
// scaled by alpha. Only the sign with which W enters the contact velocity differs
// between the wall (contact velocity v - W) and the floor (contact velocity u + W).
//
// The functions are templates on the number type so that the scalar code and the
// SIMD kernel are one piece of code, giving bit-identical results.
#pragma once

#include "model.hpp"

namespace superball {

// The four entries of the tangential impact matrix of one surface, computed once
// per model: the kernel then does two multiplications and one addition per entry,
// in the same order in every instantiation. S is the number type of the coefficients:
// double everywhere but in continuation (core/continuation.hpp), where a coefficient is
// the parameter and carries its derivative (automatic differentiation).
template <class S = double>
struct BasicImpactMatrix {
    S e;       // normal restitution
    S c_ss;    // (5 - 2 alpha)/7: tangential velocity kept
    S c_sW;    // (2/7)(1 + alpha): spin fed into the tangential velocity
    S c_Ws;    // (5/7)(1 + alpha): tangential velocity fed into the spin
    S c_WW;    // (2 - 5 alpha)/7: spin kept

    // Not declared constexpr: a defaulted comparison is constexpr where S allows it, and
    // declaring it so is an error for the S that do not (clang).
    friend bool operator==(const BasicImpactMatrix&, const BasicImpactMatrix&) = default;

    static constexpr BasicImpactMatrix of(const S& e, const S& alpha)
    {
        return {e, (5.0 - 2.0 * alpha) / 7.0, 2.0 * (1.0 + alpha) / 7.0, 5.0 * (1.0 + alpha) / 7.0,
                (2.0 - 5.0 * alpha) / 7.0};
    }
    static constexpr BasicImpactMatrix of(Surface s) { return of(S(s.e), S(s.alpha)); }
};

using ImpactMatrix = BasicImpactMatrix<double>;

template <class S = double>
struct BasicModelMatrices {
    BasicImpactMatrix<S> wall;
    BasicImpactMatrix<S> floor;

    friend bool operator==(const BasicModelMatrices&, const BasicModelMatrices&) = default;  // constexpr where S allows

    static constexpr BasicModelMatrices of(const Model& m)
    {
        return {BasicImpactMatrix<S>::of(m.wall), BasicImpactMatrix<S>::of(m.floor)};
    }
};

using ModelMatrices = BasicModelMatrices<double>;

template <class T>
struct Velocities {
    T u;  // horizontal velocity of the centre
    T v;  // vertical velocity of the centre
    T W;  // a * omega
};

// Wall impact (x = 0): u is normal, v tangential.
//   u+ = -e_wall u
//   v+ = (2/7)(1+alpha_wall) W + (1/7)(5-2 alpha_wall) v_w
//   W+ = (5/7)(1+alpha_wall) v_w + (1/7)(2-5 alpha_wall) W
template <class T, class S>
constexpr Velocities<T> wall_impact(const Velocities<T>& in, const BasicImpactMatrix<S>& wall)
{
    return {-wall.e * in.u, wall.c_sW * in.W + wall.c_ss * in.v, wall.c_Ws * in.v + wall.c_WW * in.W};
}

// Floor impact (y = 0): v is normal, u tangential.
//   u_{n+1} = (1/7)(5-2 alpha_floor) u+ - (2/7)(1+alpha_floor) W+
//   W_{n+1} = -(5/7)(1+alpha_floor) u+ + (1/7)(2-5 alpha_floor) W+
//   v_{n+1} = -e_floor v_f
template <class T, class S>
constexpr Velocities<T> floor_impact(const Velocities<T>& in, const BasicImpactMatrix<S>& floor)
{
    return {floor.c_ss * in.u - floor.c_sW * in.W, -floor.e * in.v, floor.c_WW * in.W - floor.c_Ws * in.u};
}

}  // namespace superball
