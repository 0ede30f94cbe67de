#include "region.hpp"

#include <algorithm>

#include "core/count_simd.hpp"

namespace superball::serve {

RegionWork::RegionWork(const View& v)
    : grid_(job_of(v)),
      max_bounces_(v.max_bounces),
      kernel_(kernel_for(grid_, &count_each_simd)),
      x_first_(v.plane.x < v.plane.y)
{
    out_.nx = v.x.n;
    out_.ny = v.y.n;
    out_.wall_bounces.resize(out_.nx * out_.ny);
    out_.outcomes.resize(out_.nx * out_.ny);
    // Blocks in row-major order of the grid: whole rows where a row is short, pieces of a
    // row where it is long, each at most block_points points and block_iterations impacts.
    const Extent shape = grid_.shape();
    const std::uint64_t rows = shape[0], length = shape[1];
    const std::uint64_t most = std::clamp<std::uint64_t>(block_iterations / max_bounces_, 1, block_points);
    if (length <= most) {
        const std::uint64_t per = most / length;
        for (std::uint64_t r = 0; r < rows; r += per) blocks_.push_back({{r, 0}, {std::min(per, rows - r), length}});
    } else {
        for (std::uint64_t r = 0; r < rows; ++r) {
            for (std::uint64_t c = 0; c < length; c += most) blocks_.push_back({{r, c}, {1, std::min(most, length - c)}});
        }
    }
}

void RegionWork::count_block(std::size_t b)
{
    const Box& box = blocks_[b];
    Starts starts;
    grid_.starts(box, starts);
    std::vector<ModelRun> runs;
    grid_.model_runs(box, runs);
    std::vector<std::uint32_t> counts(starts.size());
    std::vector<std::uint8_t> outcomes(starts.size());
    for (const ModelRun& run : runs) {
        kernel_(starts.view().subview(run.first, run.count), run.matrices, max_bounces_,
                std::span(counts).subspan(run.first, run.count), std::span(outcomes).subspan(run.first, run.count));
    }
    std::size_t p = 0;
    for (std::uint64_t r = box.start[0]; r < box.start[0] + box.count[0]; ++r) {
        for (std::uint64_t c = box.start[1]; c < box.start[1] + box.count[1]; ++c, ++p) {
            const std::uint64_t at = x_first_ ? c * out_.nx + r : r * out_.nx + c;
            out_.wall_bounces[at] = counts[p];
            out_.outcomes[at] = outcomes[p];
        }
    }
}

}  // namespace superball::serve
