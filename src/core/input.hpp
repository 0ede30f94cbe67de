// Resolving user input (command-line flags or job-file keys) into a Model, with
// messages that name the offending key. Shared by the command line and the job parser
// so that both accept exactly the same things.
#pragma once

#include <cstdint>
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

// The coefficients as given: `e`, `alpha` and `mu` set both surfaces, per-surface keys
// override. mu (SPEC.md 1b) defaults to infinite and inertia to 2/5: the Cross model of a
// solid ball.
struct ModelInput {
    std::optional<double> e, alpha, e_wall, alpha_wall, e_floor, alpha_floor;
    // Initialised, so that aggregates written before them ({e, alpha}) need not name them.
    std::optional<double> mu = std::nullopt, mu_wall = std::nullopt, mu_floor = std::nullopt, inertia = std::nullopt;
};

// The keys of ModelInput by name, in the order the interfaces list them: what a query, a
// dict or a job's [model] table may hold.
struct ModelKey {
    const char* name;
    std::optional<double> ModelInput::*member;
};
inline constexpr ModelKey model_input_keys[] = {
    {"e", &ModelInput::e},           {"alpha", &ModelInput::alpha},           {"e_wall", &ModelInput::e_wall},
    {"alpha_wall", &ModelInput::alpha_wall}, {"e_floor", &ModelInput::e_floor}, {"alpha_floor", &ModelInput::alpha_floor},
    {"mu", &ModelInput::mu},         {"mu_wall", &ModelInput::mu_wall},       {"mu_floor", &ModelInput::mu_floor},
    {"inertia", &ModelInput::inertia}};

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

// What a start's keys make it, before any value is read: canonical or physical, and the
// frame (g and radius, their defaults applied; a canonical start's is g = radius = 1).
struct StartKind {
    bool physical = false;
    Frame frame{1.0, 1.0};
};

// Throws InputError when the start is mixed, missing or incomplete (the first key not set,
// in the order xi U W, or omega x u v), or its frame out of range. Reads only which keys are
// set, so that an interface given arrays of starts (Python's count) refuses what the
// command line refuses, in the same words.
StartKind resolve_start_keys(const StartInput& in, const KeySpelling& spell);

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

// The bounce limit of a count or trajectory as given (a decimal integer, any size, any
// sign): 1 to 4294967295, else InputError naming the key and the value.
std::uint32_t resolve_max_bounces(std::string_view given, const KeySpelling& spell);

// What count and trajectory check before anything is counted, in the order every interface
// reports it: the coefficients, the start's keys, the bounce limit.
struct OneStartSetup {
    Model model;
    StartKind start;
    std::uint32_t max_bounces = 0;
};
OneStartSetup resolve_one_start(const ModelInput& model, const StartInput& start, std::string_view max_bounces,
                                const KeySpelling& spell);

// Shortest text that reads back as the same double (for messages and attributes).
std::string format_double(double x);

// The model as the commands print it: "e_wall 0.9 alpha_wall 0.9 e_floor 0.9 alpha_floor
// 0.9", followed by "mu_wall 1 mu_floor 1 inertia 0.5" where SPEC.md 1b's coefficients are
// not their defaults (so that the Cross model of a solid ball prints as it always did).
std::string model_text(const Model& m);

// `s` in double quotes with \" \\ \n \t and \u00XX escapes: a JSON string and a TOML basic
// string alike (for messages that quote user text, and JSON output).
std::string quote(std::string_view s);

}  // namespace superball
