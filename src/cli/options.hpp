// What the subcommands share once their options are parsed: the flags' spelling in messages,
// the start point, the output file.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

#include "core/input.hpp"
#include "core/state.hpp"

namespace superball::cli {

// "--e-wall" for the key "e_wall".
std::string flag_spelling(std::string_view key);

// resolve_start() with the flags' spelling.
Start resolve_start(const StartInput& in);

// Runs write(f) on standard output, or on the file `path` when it is not empty (-o); throws
// std::runtime_error("cannot write PATH") when the file cannot be opened or closed.
void write_output(const std::string& path, const std::function<void(std::FILE*)>& write);

}  // namespace superball::cli
