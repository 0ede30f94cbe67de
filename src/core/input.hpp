// Resolving user input (command-line flags or job-file keys) into a Model, with
// messages that name the offending key. Shared by the command line and the job parser
// so that both accept exactly the same things.
#pragma once

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "model.hpp"
#include "state.hpp"

namespace superball {

// Bad input: the message names the key, the value and what is accepted. Exit status 2.
struct InputError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

// The coefficients as given: `e` and `alpha` set both surfaces, per-surface keys override.
struct ModelInput {
    std::optional<double> e, alpha, e_wall, alpha_wall, e_floor, alpha_floor;
};

// Spells a key the way the user wrote it: "e_wall" for job files, "--e-wall" on the
// command line.
using KeySpelling = std::function<std::string(std::string_view key)>;

// Throws InputError if a coefficient is missing or out of its physical range.
Model resolve_model(const ModelInput& in, const KeySpelling& spell);

// A start point as given: canonical (xi, U, W) or physical (x, u, v, omega, with g and
// radius defaulting to Frame's).
struct StartInput {
    std::optional<double> xi, U, W;
    std::optional<double> x, u, v, omega, g, radius;
};

// A start point resolved. Canonical starts are also given as the physical representative
// with v = 1 in units where g = 1 and radius = 1 (so omega = W).
struct Start {
    bool physical = false;
    CanonicalState<double> canonical{};
    PhysicalState<double> state{};
    Frame frame{};
};

// Throws InputError naming the key when the start is incomplete, mixed or not a launch
// toward the wall.
Start resolve_start(const StartInput& in, const KeySpelling& spell);

// Shortest text that reads back as the same double (for messages and attributes).
std::string format_double(double x);

// `s` in double quotes with \" \\ \n \t and \u00XX escapes: a JSON string and a TOML basic
// string alike (for messages that quote user text, and JSON output).
std::string quote(std::string_view s);

}  // namespace superball
