#include "tile_counter.hpp"

#include <algorithm>

namespace superball {

void count_in_blocks(CountKernel kernel, const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes, const Serve& serve)
{
    // Nothing to serve: one call, so the vector kernel refills its lanes to the end instead
    // of draining them at the end of every block (4% fewer instructions with 2 lanes).
    if (!serve) {
        kernel(starts, m, max_bounces, wall_bounces, outcomes);
        return;
    }
    // Small enough that the scheduling rank answers requests within milliseconds even where
    // every point bounces to max_bounces, large enough to fill the vector kernel (512 on
    // most ranks, fewer on a rank serving many: schedule.hpp).
    const std::size_t block = std::max<std::size_t>(1, serve.points);
    for (std::size_t i = 0; i < starts.size(); i += block) {
        const std::size_t n = std::min(block, starts.size() - i);
        kernel(starts.subview(i, n), m, max_bounces, wall_bounces.subspan(i, n), outcomes.subspan(i, n));
        serve();
    }
}

void TileCounter::all(const Starts& starts, const std::vector<ModelRun>& runs, std::span<std::uint32_t> wall_bounces,
                      std::span<std::uint8_t> outcomes, const Serve& serve) const
{
    for (const ModelRun& run : runs) {
        count_in_blocks(kernel_, starts.view().subview(run.first, run.count), run.matrices, max_bounces_,
                        wall_bounces.subspan(run.first, run.count), outcomes.subspan(run.first, run.count), serve);
    }
}

void TileCounter::some(std::span<const std::uint64_t> points, const Starts& starts, const std::vector<ModelRun>& runs,
                       std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes, const Serve& serve)
{
    auto next = points.begin();
    for (const ModelRun& run : runs) {
        // The points of this run, gathered, counted and scattered back.
        const auto end = std::lower_bound(next, points.end(), run.first + run.count);
        subset_.clear();
        for (auto p = next; p != end; ++p) subset_.push_back(starts.view()[*p]);
        counts_.resize(subset_.size());
        outcomes_.resize(subset_.size());
        count_in_blocks(kernel_, subset_.view(), run.matrices, max_bounces_, counts_, outcomes_, serve);
        for (std::size_t j = 0; next != end; ++next, ++j) {
            wall_bounces[*next] = counts_[j];
            outcomes[*next] = outcomes_[j];
        }
    }
}

}  // namespace superball
