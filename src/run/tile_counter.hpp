// Counting the points of one tile with a kernel, model run by model run.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"
#include "job/grid.hpp"
#include "run/schedule.hpp"

namespace superball {

// Runs `kernel` over `starts` in blocks, calling `serve` between blocks; in one call when
// `serve` is empty (no rank is waiting to be served).
void count_in_blocks(CountKernel kernel, const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes, const Serve& serve);

class TileCounter {
public:
    TileCounter(CountKernel kernel, std::uint32_t max_bounces) : kernel_(kernel), max_bounces_(max_bounces) {}

    // Every point of the tile: starts[i] -> wall_bounces[i], outcomes[i].
    void all(const Starts& starts, const std::vector<ModelRun>& runs, std::span<std::uint32_t> wall_bounces,
             std::span<std::uint8_t> outcomes, const Serve& serve) const;

    // Only `points` (ascending indices into the tile).
    void some(std::span<const std::uint64_t> points, const Starts& starts, const std::vector<ModelRun>& runs,
              std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes, const Serve& serve);

private:
    CountKernel kernel_;
    std::uint32_t max_bounces_;
    // Gathered points of one run, reused from call to call.
    Starts subset_;
    std::vector<std::uint32_t> counts_;
    std::vector<std::uint8_t> outcomes_;
};

}  // namespace superball
