// Command-line options shared by the subcommands: the model flags and the start point.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include "core/input.hpp"
#include "core/state.hpp"

namespace superball::cli {

// "--e-wall" for the key "e_wall".
std::string flag_spelling(std::string_view key);

void add_model_flags(CLI::App& app, ModelInput& in);

using StartFlags = StartInput;

void add_start_flags(CLI::App& app, StartFlags& in);

// resolve_start() with the flags' spelling.
Start resolve_start(const StartFlags& in);

void add_max_bounces_flag(CLI::App& app, std::uint32_t& max_bounces);

// Runs write(f) on standard output, or on the file `path` when it is not empty (-o); throws
// std::runtime_error("cannot write PATH") when the file cannot be opened or closed.
void write_output(const std::string& path, const std::function<void(std::FILE*)>& write);

}  // namespace superball::cli
