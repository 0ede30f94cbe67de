// JSON texts of results, written by one function for the command line (count --json,
// trajectory --format json) and the server (/api/count, /api/trajectory, the model in its
// other documents), so the two cannot drift apart. Through nlohmann-json: numbers are the
// shortest text that reads back as the same double.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "core/count.hpp"
#include "core/input.hpp"

namespace superball {

// Declared, not included: this header's users need not compile core/trajectory.hpp.
struct Trajectory;

// {"e_wall": ..., "alpha_wall": ..., "e_floor": ..., "alpha_floor": ...}
nlohmann::ordered_json model_json(const Model& m);

// {"wall_bounces": N, "outcome": "left", "xi": ..., "U": ..., "W": ...} and a newline.
std::string count_json(const BounceCount& r, const CanonicalState<double>& start);

// Units, g and radius, model, start, result, every event and the flight-path samples of
// `tr`, the trajectory of `start` under `m`, and a newline. Spins are given as
// omega = W / radius.
std::string trajectory_json(const Trajectory& tr, const Start& start, const Model& m);

}  // namespace superball
