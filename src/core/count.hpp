// Counting wall bounces (SPEC.md section 3).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

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

// Many canonical starts, one array per coordinate: the layout from which the vectorised
// kernel loads whole batches.
struct StartsView {
    std::span<const double> xi, U, W;

    std::size_t size() const { return xi.size(); }
    CanonicalState<double> operator[](std::size_t i) const { return {xi[i], U[i], W[i]}; }
    StartsView subview(std::size_t first, std::size_t n) const
    {
        return {xi.subspan(first, n), U.subspan(first, n), W.subspan(first, n)};
    }
};

struct Starts {
    std::vector<double> xi, U, W;

    static Starts of(std::span<const CanonicalState<double>> states)
    {
        Starts out;
        out.reserve(states.size());
        for (const CanonicalState<double>& c : states) out.push_back(c);
        return out;
    }

    std::size_t size() const { return xi.size(); }
    void clear()
    {
        xi.clear();
        U.clear();
        W.clear();
    }
    void reserve(std::size_t n)
    {
        xi.reserve(n);
        U.reserve(n);
        W.reserve(n);
    }
    void resize(std::size_t n)
    {
        xi.resize(n);
        U.resize(n);
        W.resize(n);
    }
    void set(std::size_t i, const CanonicalState<double>& c)
    {
        xi[i] = c.xi;
        U[i] = c.U;
        W[i] = c.W;
    }
    void push_back(const CanonicalState<double>& c)
    {
        xi.push_back(c.xi);
        U.push_back(c.U);
        W.push_back(c.W);
    }
    StartsView view() const { return {xi, U, W}; }
};

// count() of every start: wall_bounces[i], outcome[i] for starts[i]. The batch form the
// explorer calls per block of a tile; count_each_simd() is its vectorised twin.
void count_each(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes);

// The limit of count() as xi -> 0+ or xi -> 1-, for starts on a boundary plane (xi
// exactly 0 or 1; anything else is invalid): the first excursion is G's limit there.
BounceCount count_on_plane(const CanonicalState<double>& start, const ModelMatrices& m, std::uint32_t max_bounces);

// count_on_plane() of every start, with count_each()'s contract (scalar: plane grids are
// 2-D and cheap).
void count_each_on_plane(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                         std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes);

// Physical start: converted to canonical coordinates; not a launch -> invalid.
BounceCount count(const PhysicalState<double>& start, const Model& m, double g, std::uint32_t max_bounces);

}  // namespace superball
