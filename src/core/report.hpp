// JSON texts of results, written by one function for the command line (count --json,
// trajectory --format json) and the server (/api/count, /api/trajectory), so the two
// cannot drift apart. Numbers are the shortest text that reads back as the same double.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "count.hpp"
#include "input.hpp"
#include "trajectory.hpp"

namespace superball {

// {"e_wall": ..., "alpha_wall": ..., "e_floor": ..., "alpha_floor": ...}
std::string model_json(const Model& m);

// {"wall_bounces": N, "outcome": "left", "xi": ..., "U": ..., "W": ...}
std::string count_json(const BounceCount& r, const CanonicalState<double>& start);

// Units, g and radius, model, start, result, every event and the flight-path samples of
// `tr`, the trajectory of `start` under `m`. Spins are given as omega = W / radius.
std::string trajectory_json(const Trajectory& tr, const Start& start, const Model& m);

// One row of a trajectory's table (`superball trajectory --format csv`, the Python module's
// trajectory()): an event, or a point sampled on a flight (event "path": the velocity at the
// sample on both sides, the wall impacts and spin of the flight's start). Spins are
// omega = W / radius.
struct TrajectoryRow {
    std::string_view event;
    std::uint32_t wall_bounces;
    double t, x, y, u_in, v_in, omega_in, u, v, omega;
};

// The table's columns, in order: the CSV's header.
inline constexpr const char* trajectory_columns = "event,wall_bounces,t,x,y,u_in,v_in,omega_in,u,v,omega";

// Every event of `tr`, then every path sample.
std::vector<TrajectoryRow> trajectory_rows(const Trajectory& tr, double radius);

}  // namespace superball
