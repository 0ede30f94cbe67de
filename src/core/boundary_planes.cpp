#include "boundary_planes.hpp"

#include <cmath>

namespace superball {

namespace {

// Both planes: the wall is hit at floor level (y -> 0) with vertical velocity v_w (+1 or
// -1 for the representative v = 1, g = 1 of canonical_map). See boundary_planes.md.
PlaneStep plane_map(double v_w, double U, double W, const ModelMatrices& m)
{
    const Velocities<double> after_wall = walton_wall_impact(Velocities<double>{U, v_w, W}, m.wall);
    const double p = after_wall.v;
    // From height 0 the ball is back on the floor with vertical speed |p|.
    const Velocities<double> after_floor =
        walton_floor_impact(Velocities<double>{after_wall.u, -std::fabs(p), after_wall.W}, m.floor);
    PlaneStep r;
    r.p = p;
    r.lambda = after_floor.v;
    r.U = after_floor.u / r.lambda;
    r.W = after_floor.W / r.lambda;
    // Going up, the flight back takes T = 2p and xi' = u+ T / (2 |u'| lambda), T and
    // lambda both proportional to p. Going down from height y ~ 2 d it takes
    // T ~ y / |p| = 2 d / |p|, one factor p^2 less: xi' / d tends to the same expression
    // divided by p^2.
    const double xi_up = after_wall.u / (-after_floor.u * m.floor.e);
    r.to_corner = p < 0.0;
    r.xi = r.to_corner ? xi_up / (p * p) : xi_up;
    return r;
}

}  // namespace

PlaneStep plane_map_xi0(double U, double W, const ModelMatrices& m) { return plane_map(1.0, U, W, m); }

PlaneStep plane_map_xi1(double U, double W, const ModelMatrices& m) { return plane_map(-1.0, U, W, m); }

}  // namespace superball
