// Counting the points of a view: the job explore would run for it, cut into blocks that
// the worker pool's threads count in any order and side by side.
#pragma once

#include <cstdint>
#include <vector>

#include "job/grid.hpp"
#include "view.hpp"

namespace superball::serve {

// Counts and outcome codes of a view, row-major with rows along y: point (i, j), the i-th
// sample of x and the j-th of y, is at j * nx + i.
struct RegionCounts {
    std::uint64_t nx = 0;
    std::uint64_t ny = 0;
    std::vector<std::uint32_t> wall_bounces;
    std::vector<std::uint8_t> outcomes;
};

// Wall impacts a block may take at most (every point capped): 0.02-0.06 s of one core, the
// time a cancelled or timed-out request may still run on.
inline constexpr std::uint64_t block_iterations = std::uint64_t{1} << 22;
inline constexpr std::uint64_t block_points = 4096;

class RegionWork {
public:
    // The grid of job_of(v): samples by Range::sample, counted by the kernel kernel_for()
    // chooses for it, as `superball explore` counts the same job.
    explicit RegionWork(const View& v);

    std::size_t blocks() const { return blocks_.size(); }
    // Counts block b into the result. Distinct blocks may be counted concurrently.
    void count_block(std::size_t b);
    // The result, once every block is counted.
    RegionCounts take() { return std::move(out_); }

private:
    Grid grid_;
    std::uint32_t max_bounces_;
    CountKernel kernel_;
    bool x_first_;  // the grid's first axis is x (results are transposed into rows along y)
    std::vector<Box> blocks_;
    RegionCounts out_;
};

}  // namespace superball::serve
