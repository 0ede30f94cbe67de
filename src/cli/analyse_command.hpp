// superball analyse: the structure of the regions of a 2-D result (run/analyse.hpp).
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace superball::cli {

struct AnalyseOptions {
    std::string file;
    std::string slice;
    std::size_t box = 5;
    std::optional<std::size_t> eps_max;
    std::optional<std::size_t> box_max;
    std::size_t top = 5;
    bool with_outcome = false;
    bool json = false;
};

int analyse_command(const AnalyseOptions& opt);

}  // namespace superball::cli
