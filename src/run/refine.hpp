// Adaptive computation of a tile ([run] refine = s): every s-th point first, then only
// the cells whose corners disagree are subdivided, halving the stride down to 1; cells
// whose corners all agree (same wall-bounce count and outcome) take that value without
// computing their interior. The result is on the full grid, like a full computation,
// but structures smaller than the coarse stride that touch no coarse point can be
// missed: tests/bench/run.sh measures the mismatch rate and the speed-up.
#pragma once

#include <cstdint>
#include <functional>
#include <span>

#include "job/tiles.hpp"

namespace superball {

// Counts the listed points of the tile (ascending indices) into the result arrays.
using CountPoints = std::function<void(std::span<const std::uint64_t> points)>;

// Fills wall_bounces/outcomes for every point of a tile of `shape` (row-major),
// computing through `count` only what the refinement needs; returns the number of
// points computed. stride: a power of two >= 2.
std::uint64_t refine_tile(const Extent& shape, std::uint32_t stride, const CountPoints& count,
                          std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes);

}  // namespace superball
