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

#include "core/count.hpp"
#include "tiles.hpp"

namespace superball {

// count_each() or count_each_simd().
using CountKernel = void (*)(const StartsView&, const ModelMatrices&, std::uint32_t, std::span<std::uint32_t>,
                             std::span<std::uint8_t>);

// Runs `kernel` over `starts` in blocks, calling `serve` between blocks (rank 0 answers
// the other ranks' requests there).
void count_in_blocks(CountKernel kernel, const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes,
                     const std::function<void()>& serve);

// Fills wall_bounces/outcomes for every point of a tile of `shape` (row-major, `starts`
// holds all its points) computing only what the refinement needs; returns the number of
// points computed. stride: a power of two >= 2.
std::uint64_t refine_tile(const Extent& shape, const StartsView& starts, std::uint32_t stride, CountKernel kernel,
                          const ModelMatrices& m, std::uint32_t max_bounces, std::span<std::uint32_t> wall_bounces,
                          std::span<std::uint8_t> outcomes, const std::function<void()>& serve);

}  // namespace superball
