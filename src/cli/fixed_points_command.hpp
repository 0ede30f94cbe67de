// superball fixed-points: fixed points and cycles of the canonical map (run/cycles.hpp).
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <cstdint>
#include <string>

#include "core/input.hpp"

namespace superball::cli {

struct FixedPointOptions {
    ModelInput model;
    int period = 1;
    std::int64_t starts = 2000;
    std::uint64_t seed = 1;
    std::string format = "table";
    std::string output;
    bool corner = false;
};

int fixed_points_command(const FixedPointOptions& opt);

}  // namespace superball::cli
