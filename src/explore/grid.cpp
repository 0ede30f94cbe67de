#include "grid.hpp"

#include <algorithm>
#include <limits>

namespace superball {

Grid::Grid(const Job& job) : coordinates_(job.coordinates), frame_(job.frame)
{
    for (std::size_t i = 0; i < job.grid.size(); ++i) {
        const Coordinate& c = job.grid[i];
        fixed_.push_back(c.fixed.value_or(0.0));
        if (!c.is_range()) continue;
        range_index_.push_back(i);
        std::vector<double> s(c.range->n);
        for (std::uint64_t k = 0; k < c.range->n; ++k) s[k] = c.range->sample(k);
        samples_.push_back(std::move(s));
    }
}

Tiling default_tiling(const Job& job, int ranks)
{
    Extent shape;
    for (const Coordinate* c : job.range_axes()) shape.push_back(c->range->n);
    const std::uint64_t points = job.tile_points.value_or(default_tile_points(job.points(), job.refine ? 1 : ranks));
    return Tiling(shape, default_tile_shape(shape, points));
}

Extent Grid::shape() const
{
    Extent e;
    for (const auto& s : samples_) e.push_back(s.size());
    return e;
}

CanonicalState<double> Grid::canonical(const std::vector<double>& c) const
{
    if (coordinates_ == Coordinates::canonical) return {c[0], c[1], c[2]};
    const PhysicalState<double> s{c[0], c[1], c[2], c[3] * frame_.radius};
    if (!is_launch(s)) {
        constexpr double nan = std::numeric_limits<double>::quiet_NaN();
        return {nan, nan, nan};
    }
    return to_canonical(s, frame_.g);
}

void Grid::starts(const Box& box, Starts& out) const
{
    out.resize(box.points());
    std::vector<double> coords = fixed_;
    const std::size_t d = samples_.size();
    const std::size_t last = d - 1;
    const double* fastest = samples_[last].data() + box.start[last];
    double& varying = coords[range_index_[last]];
    std::size_t p = 0;
    // Odometer over every axis but the last; the last axis is the inner loop.
    Extent index(d, 0);
    for (;;) {
        for (std::size_t k = 0; k < last; ++k) coords[range_index_[k]] = samples_[k][box.start[k] + index[k]];
        const std::uint64_t row = box.count[last];
        if (coordinates_ == Coordinates::canonical) {
            // A row of canonical starts is two constant arrays and one copied axis: no
            // per-point work (this loop was 10% of a run when done point by point).
            std::vector<double>* arrays[] = {&out.xi, &out.U, &out.W};
            for (std::size_t c = 0; c < 3; ++c) {
                double* dst = arrays[c]->data() + p;
                if (c == range_index_[last]) {
                    std::copy(fastest, fastest + row, dst);
                } else {
                    std::fill(dst, dst + row, coords[c]);
                }
            }
            p += row;
        } else {
            for (std::uint64_t j = 0; j < row; ++j) {
                varying = fastest[j];
                out.set(p++, canonical(coords));
            }
        }
        std::size_t k = last;
        while (k-- > 0) {
            if (++index[k] < box.count[k]) break;
            index[k] = 0;
        }
        if (k == static_cast<std::size_t>(-1)) return;
    }
}

}  // namespace superball
