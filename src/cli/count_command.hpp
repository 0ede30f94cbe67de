// superball count: the wall bounces of one start point.
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <cstdint>
#include <string>

#include "core/input.hpp"

namespace superball::cli {

struct CountOptions {
    ModelInput model;
    StartInput start;
    std::string max_bounces = "1000";  // as given: resolve_max_bounces checks it
    bool json = false;
};

int count_command(const CountOptions& opt);

}  // namespace superball::cli
