// superball continue: branches of cycles followed in one coefficient (run/continuation.hpp).
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <string>

#include "run/continuation.hpp"

namespace superball::cli {

// The flags: those of the library's ContinuationInput, --start as text, the output's.
struct ContinueOptions {
    ContinuationInput in;
    std::string start;
    std::string format = "csv";
    std::string output;
};

int continue_command(const ContinueOptions& opt);

}  // namespace superball::cli
