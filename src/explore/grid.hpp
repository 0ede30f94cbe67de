// The points of a job's grid, tile by tile, as canonical launch states.
#pragma once

#include <span>
#include <vector>

#include "core/count.hpp"
#include "job.hpp"
#include "tiles.hpp"

namespace superball {

class Grid {
public:
    explicit Grid(const Job& job);

    Extent shape() const;
    std::size_t dimensions() const { return samples_.size(); }
    // Sample values of range axis k (cell centres, Range::sample).
    const std::vector<double>& samples(std::size_t k) const { return samples_[k]; }

    // The canonical start of every point of `box`, row-major (last axis fastest).
    // Physical points that are not a launch toward the wall become a non-admissible
    // canonical state (NaN), which count() reports as invalid.
    void starts(const Box& box, Starts& out) const;

private:
    CanonicalState<double> canonical(const std::vector<double>& coords) const;

    Coordinates coordinates_;
    Frame frame_;
    std::vector<double> fixed_;              // every coordinate; ranges overwritten per point
    std::vector<std::size_t> range_index_;   // which coordinate each range axis is
    std::vector<std::vector<double>> samples_;
};

// The tiling of a new result: [run] tile_points, or a default from the grid size and the
// rank count. With refinement the results depend on the tile shape (cells do not cross
// tiles), so there the default ignores the rank count: any number of ranks gives the
// same file.
Tiling default_tiling(const Job& job, int ranks);

}  // namespace superball
