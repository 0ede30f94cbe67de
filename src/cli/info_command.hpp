// superball info: what a result or partial file says about itself, validated.
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <string>

namespace superball::cli {

struct InfoOptions {
    std::string file;  // a result, its partial file, or a result's name whose run is unfinished
};

int info_command(const InfoOptions& opt);

}  // namespace superball::cli
