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
// in the same order in every instantiation.
struct ImpactMatrix {
    double e;       // normal restitution
    double c_ss;    // (5 - 2 alpha)/7: tangential velocity kept
    double c_sW;    // (2/7)(1 + alpha): spin fed into the tangential velocity
    double c_Ws;    // (5/7)(1 + alpha): tangential velocity fed into the spin
    double c_WW;    // (2 - 5 alpha)/7: spin kept

    friend constexpr bool operator==(const ImpactMatrix&, const ImpactMatrix&) = default;

    static constexpr ImpactMatrix of(Surface s)
    {
        return {s.e, (5.0 - 2.0 * s.alpha) / 7.0, 2.0 * (1.0 + s.alpha) / 7.0,
                5.0 * (1.0 + s.alpha) / 7.0, (2.0 - 5.0 * s.alpha) / 7.0};
    }
};

struct ModelMatrices {
    ImpactMatrix wall;
    ImpactMatrix floor;

    friend constexpr bool operator==(const ModelMatrices&, const ModelMatrices&) = default;

    static constexpr ModelMatrices of(const Model& m) { return {ImpactMatrix::of(m.wall), ImpactMatrix::of(m.floor)}; }
};

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
template <class T>
constexpr Velocities<T> wall_impact(const Velocities<T>& in, const ImpactMatrix& wall)
{
    return {-wall.e * in.u, wall.c_sW * in.W + wall.c_ss * in.v, wall.c_Ws * in.v + wall.c_WW * in.W};
}

// Floor impact (y = 0): v is normal, u tangential.
//   u_{n+1} = (1/7)(5-2 alpha_floor) u+ - (2/7)(1+alpha_floor) W+
//   W_{n+1} = -(5/7)(1+alpha_floor) u+ + (1/7)(2-5 alpha_floor) W+
//   v_{n+1} = -e_floor v_f
template <class T>
constexpr Velocities<T> floor_impact(const Velocities<T>& in, const ImpactMatrix& floor)
{
    return {floor.c_ss * in.u - floor.c_sW * in.W, -floor.e * in.v, floor.c_WW * in.W - floor.c_Ws * in.u};
}

}  // namespace superball
