// The canonical map G on the planes that bound its region 0 < xi < 1 (derivation in
// boundary_planes.md).
//
//   xi -> 0+: launch at the wall. The flight to the wall takes no time and the wall is
//             hit at floor level going up (v_w = 1).
//   xi -> 1-: the wall is hit at floor level on the way down (v_w = -1).
//
// On both planes (U', W') and lambda tend to finite limits, functions of (U, W) alone.
// What xi' does depends on the vertical velocity p with which the ball leaves the wall:
// going up (p > 0) it flies a full parabola and xi' tends to a finite value; going down
// (p < 0) it lands at once, next to the corner, and xi' -> 0 in proportion to the
// distance d from the plane (d = xi, resp. 1 - xi). So the part p < 0 of the plane xi = 0
// is mapped into itself, with the transverse multiplier xi'/xi, and the part p < 0 of the
// plane xi = 1 is mapped onto the plane xi = 0. p = 0 is singular (lambda -> 0).
#pragma once

#include "impact.hpp"

namespace superball {

struct PlaneStep {
    double U = 0.0;       // lim U'
    double W = 0.0;       // lim W'
    double lambda = 0.0;  // lim lambda = e_floor |p|
    double p = 0.0;       // vertical velocity leaving the wall, in the limit (v = 1 at launch)
    // p < 0: the next launch is at the corner plane, xi' -> 0 like `xi` times d.
    bool to_corner = false;
    // to_corner: lim xi' / d; otherwise lim xi'. Meaningful when U < 0 (the ball heads
    // back to the wall), like xi' itself.
    double xi = 0.0;
};

// lim G(xi, U, W) as xi -> 0+ (launch at the wall).
PlaneStep plane_map_xi0(double U, double W, const ModelMatrices& m);

// lim G(xi, U, W) as xi -> 1- (wall hit at floor level); d = 1 - xi.
PlaneStep plane_map_xi1(double U, double W, const ModelMatrices& m);

}  // namespace superball
