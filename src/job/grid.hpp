// The points of a job's grid, tile by tile: canonical launch states, and the model of
// each point (which varies along swept coefficients).
#pragma once

#include <span>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"
#include "job.hpp"
#include "tiles.hpp"

namespace superball {

// Consecutive points of a box (row-major) that share one model.
struct ModelRun {
    std::size_t first = 0;
    std::size_t count = 0;
    ModelMatrices matrices{};
};

class Grid {
public:
    explicit Grid(Job job);

    Extent shape() const;
    std::size_t dimensions() const { return axes_.size(); }
    // Sample values of range axis k (cell centres, Range::sample).
    const std::vector<double>& samples(std::size_t k) const { return axes_[k].samples; }

    // The canonical start of every point of `box`, row-major (last axis fastest).
    // Physical points that are not a launch toward the wall become a non-admissible
    // canonical state (NaN), which count() reports as invalid.
    void starts(const Box& box, Starts& out) const;

    // A canonical grid with xi fixed at exactly 0 or 1 lies on a boundary plane: its points
    // are counted as limits from inside (count_on_plane), not as the invalid launches
    // (xi = 0) or immediate misses (xi = 1) they would be.
    bool on_boundary_plane() const;

    // The points of `box` grouped by model: one run when no coefficient is swept.
    void model_runs(const Box& box, std::vector<ModelRun>& out) const;

private:
    struct Axis {
        int coordinate = -1;  // index in the job's coordinates, or -1
        int parameter = -1;   // index in the job's swept parameters, or -1
        std::vector<double> samples;
    };

    CanonicalState<double> canonical(const std::vector<double>& coords) const;

    Job job_;
    std::vector<double> fixed_;  // every coordinate; ranges overwritten per point
    std::vector<Axis> axes_;     // the range axes, in result order
};

// The kernel that counts `grid`'s points, given the one chosen for a run (a variant of
// core/kernels.hpp): count_each_on_plane() on a boundary plane. Every front end (explore, serve)
// counts through this, so the same grid gives the same numbers everywhere.
CountKernel kernel_for(const Grid& grid, CountKernel chosen);

// The tiling of a new result: [run] tile_points, or a default from the grid size and the
// rank count. With refinement the results depend on the tile shape (cells do not cross
// tiles), so there the default ignores the rank count: any number of ranks gives the
// same file. InputError if it makes more than max_run_tiles tiles (job/tiles.hpp).
Tiling default_tiling(const Job& job, int ranks);

}  // namespace superball
