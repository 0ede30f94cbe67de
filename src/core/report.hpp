// JSON texts of results, written by one function for the command line (count --json,
// trajectory --format json) and the server (/api/count, /api/trajectory), so the two
// cannot drift apart. Numbers are the shortest text that reads back as the same double.
#pragma once

#include <string>

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

}  // namespace superball
