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

struct StartFlags {
    std::optional<double> xi, U, W;                // canonical
    std::optional<double> x, u, v, omega, g, radius;  // physical
};

void add_start_flags(CLI::App& app, StartFlags& in);

// A start point as the user gave it. Canonical starts are also given as the physical
// representative with v = 1 in units where g = 1 and radius = 1 (so omega = W).
struct Start {
    bool physical = false;
    CanonicalState<double> canonical{};
    PhysicalState<double> state{};
    Frame frame{};
};

// Throws InputError naming the flag when the start is incomplete, mixed or not a launch
// toward the wall.
Start resolve_start(const StartFlags& in);

void add_max_bounces_flag(CLI::App& app, std::uint32_t& max_bounces);

// Runs write(f) on standard output, or on the file `path` when it is not empty (-o); throws
// std::runtime_error("cannot write PATH") when the file cannot be opened or closed.
void write_output(const std::string& path, const std::function<void(std::FILE*)>& write);

}  // namespace superball::cli
