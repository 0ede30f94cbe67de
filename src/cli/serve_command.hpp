// superball serve: the explorer in a browser (serve/server.hpp).
// main.cpp (the only file that knows the command line) parses the options into the struct;
// the function runs the command: returns the process exit status, throws InputError for bad
// input (status 2).
#pragma once

#include <string>
#include <vector>

#include "serve/server.hpp"

namespace superball::cli {

struct ServeOptions {
    std::vector<std::string> layers;
    serve::ServeSettings settings;
};

int serve_command(const ServeOptions& opt);

}  // namespace superball::cli
