// Counting wall bounces (SPEC.md section 3).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "map.hpp"

namespace superball {

// Stored as uint8 in result files: the numbers are part of the file format.
enum class Outcome : std::uint8_t {
    invalid = 0,  // not an admissible launch
    left = 1,     // after the N-th wall impact the floor bounce sent the ball away
    missed = 2,   // heading to the wall, the ball landed on the floor first
    capped = 3,   // N reached max_bounces and the next excursion would hit the wall again
};

inline constexpr int outcome_count = 4;

constexpr std::string_view name(Outcome o)
{
    switch (o) {
        case Outcome::invalid: return "invalid";
        case Outcome::left: return "left";
        case Outcome::missed: return "missed";
        case Outcome::capped: return "capped";
    }
    return "unknown";
}

std::optional<Outcome> outcome_from_name(std::string_view s);

struct BounceCount {
    std::uint32_t wall_bounces = 0;
    Outcome outcome = Outcome::invalid;

    friend bool operator==(const BounceCount&, const BounceCount&) = default;
};

// Iterates G from `start` until the ball leaves, misses the wall, or has hit the wall
// max_bounces times. Iterating the canonical map (rather than F) keeps the state O(1)
// however many bounces shrink the physical velocities.
BounceCount count(const CanonicalState<double>& start, const ModelMatrices& m, std::uint32_t max_bounces);

inline BounceCount count(const CanonicalState<double>& start, const Model& m, std::uint32_t max_bounces)
{
    return count(start, ModelMatrices::of(m), max_bounces);
}

// count() of every start: wall_bounces[i], outcome[i] for starts[i]. The batch form the
// explorer calls per block of a tile (and the entry point of the vectorised kernel).
void count_each(std::span<const CanonicalState<double>> starts, const ModelMatrices& m, std::uint32_t max_bounces,
                std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes);

// Physical start: converted to canonical coordinates; not a launch -> invalid.
BounceCount count(const PhysicalState<double>& start, const Model& m, double g, std::uint32_t max_bounces);

}  // namespace superball
