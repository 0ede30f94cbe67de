// A trajectory as the rows of a table: `superball trajectory --format csv` and the Python
// module's trajectory(). (Its JSON text is job/result_json.hpp's.)
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "count.hpp"
#include "input.hpp"
#include "trajectory.hpp"

namespace superball {

// One row of a trajectory's table (`superball trajectory --format csv`, the Python module's
// trajectory()): an event, or a point sampled on a flight (event "path": the velocity at the
// sample on both sides, the wall impacts and spin of the flight's start). Spins are
// omega = W / radius.
// Impacts (wall, floor) say whether they gripped or slid (SPEC.md 1b) and their tangential
// factor beta; other rows have contact "" and beta NaN.
struct TrajectoryRow {
    std::string_view event;
    std::uint32_t wall_bounces;
    double t, x, y, u_in, v_in, omega_in, u, v, omega;
    std::string_view contact;
    double beta;
};

// The table's columns, in order: the CSV's header.
inline constexpr const char* trajectory_columns = "event,wall_bounces,t,x,y,u_in,v_in,omega_in,u,v,omega,contact,beta";

// Every event of `tr`, then every path sample.
std::vector<TrajectoryRow> trajectory_rows(const Trajectory& tr, double radius);

}  // namespace superball
