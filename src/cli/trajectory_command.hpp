// superball trajectory: every impact of one start point (CSV or JSON).
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <cstdint>
#include <string>

#include "core/input.hpp"

namespace superball::cli {

struct TrajectoryOptions {
    ModelInput model;
    StartInput start;
    std::string max_bounces = "1000";  // as given: resolve_max_bounces checks it
    std::string format = "csv";
    int samples = 0;
    std::string output;
};

int trajectory_command(const TrajectoryOptions& opt);

}  // namespace superball::cli
