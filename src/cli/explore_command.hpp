// superball explore: wall bounces over a grid of starts (run/explore.hpp).
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <string>

namespace superball::cli {

struct ExploreOptions {
    std::string job;
    std::string output;
    bool resume = false;
    bool overwrite = false;
    bool quiet = false;
    bool dry_run = false;
    bool stats = false;
    int node_ranks = 0;      // 0: the ranks sharing memory form a node
    double stop_after = -1;  // seconds of computing, then a clean stop; < 0: none
    std::string kernel;      // empty: $SUPERBALL_KERNEL, else the best variant
    std::string writers;     // "auto" or a count; empty: the job's [run] writers
};

int explore_command(const ExploreOptions& opt);

}  // namespace superball::cli
