#include "grid.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <limits>

namespace superball {

namespace {

std::vector<double> samples_of(const Range& r)
{
    std::vector<double> s(r.n);
    for (std::uint64_t k = 0; k < r.n; ++k) s[k] = r.sample(k);
    return s;
}

// Calls f(index) for the multi-index of the first point of every row of `box` along its
// last axis, in row-major order.
template <class F>
void for_each_row(const Box& box, F&& f)
{
    const std::size_t d = box.count.size();
    Extent index(d, 0);
    for (;;) {
        f(index);
        std::size_t k = d - 1;
        while (k-- > 0) {
            if (++index[k] < box.count[k]) break;
            index[k] = 0;
        }
        if (k == static_cast<std::size_t>(-1)) return;
    }
}

}  // namespace

Grid::Grid(Job job) : job_(std::move(job))
{
    for (std::size_t p = 0; p < job_.parameters.size(); ++p) {
        axes_.push_back({-1, static_cast<int>(p), samples_of(*job_.parameters[p].range)});
    }
    for (std::size_t i = 0; i < job_.grid.size(); ++i) {
        const Coordinate& c = job_.grid[i];
        fixed_.push_back(c.fixed.value_or(0.0));
        if (c.is_range()) axes_.push_back({static_cast<int>(i), -1, samples_of(*c.range)});
    }
}

Tiling default_tiling(const Job& job, int ranks)
{
    Extent shape;
    for (const Coordinate* c : job.range_axes()) shape.push_back(c->range->n);
    const std::uint64_t points = job.tile_points.value_or(default_tile_points(job.points(), job.refine ? 1 : ranks));
    Tiling tiling(shape, default_tile_shape(shape, points));
    if (tiling.tiles() > max_run_tiles) {
        throw InputError(fmt::format("this grid's {} points in tiles of {} points make {} tiles: a run takes at most {} "
                                     "(2^30); [run] tile_points = {} or more makes fewer",
                                     job.points(), tiling.tile_points(), tiling.tiles(), max_run_tiles,
                                     (job.points() + max_run_tiles - 1) / max_run_tiles * 2));
    }
    return tiling;
}

CountKernel kernel_for(const Grid& grid, CountKernel chosen)
{
    return grid.on_boundary_plane() ? &count_each_on_plane : chosen;
}

bool Grid::on_boundary_plane() const
{
    if (job_.coordinates != Coordinates::canonical) return false;
    const std::optional<double>& xi = job_.grid[0].fixed;
    return xi && (*xi == 0.0 || *xi == 1.0);
}

Extent Grid::shape() const
{
    Extent e;
    for (const Axis& a : axes_) e.push_back(a.samples.size());
    return e;
}

CanonicalState<double> Grid::canonical(const std::vector<double>& c) const
{
    if (job_.coordinates == Coordinates::canonical) return {c[0], c[1], c[2]};
    return canonical_launch({c[0], c[1], c[2], c[3] * job_.frame.radius}, job_.frame.g);
}

void Grid::starts(const Box& box, Starts& out) const
{
    out.resize(box.points());
    std::vector<double> coords = fixed_;
    const std::size_t last = axes_.size() - 1;
    const Axis& inner = axes_[last];
    const std::uint64_t row = box.count[last];
    std::size_t p = 0;
    for_each_row(box, [&](const Extent& index) {
        for (std::size_t k = 0; k < last; ++k) {
            if (axes_[k].coordinate >= 0) coords[static_cast<std::size_t>(axes_[k].coordinate)] = axes_[k].samples[box.start[k] + index[k]];
        }
        const double* fastest = inner.samples.data() + box.start[last];
        if (job_.coordinates == Coordinates::canonical) {
            // A row of canonical starts is constant arrays and at most one copied axis: no
            // per-point work (this loop was 10% of a run when done point by point).
            std::vector<double>* arrays[] = {&out.xi, &out.U, &out.W};
            for (int c = 0; c < 3; ++c) {
                double* dst = arrays[c]->data() + p;
                if (c == inner.coordinate) {
                    std::copy(fastest, fastest + row, dst);
                } else {
                    std::fill(dst, dst + row, coords[static_cast<std::size_t>(c)]);
                }
            }
        } else {
            for (std::uint64_t j = 0; j < row; ++j) {
                if (inner.coordinate >= 0) coords[static_cast<std::size_t>(inner.coordinate)] = fastest[j];
                out.set(p + j, canonical(coords));
            }
        }
        p += row;
    });
}

void Grid::model_runs(const Box& box, std::vector<ModelRun>& out) const
{
    out.clear();
    if (job_.parameters.empty()) {
        out.push_back({0, box.points(), ModelMatrices::of(job_.model)});
        return;
    }
    std::vector<double> values(job_.parameters.size());
    const std::size_t last = axes_.size() - 1;
    const std::uint64_t row = box.count[last];
    std::size_t p = 0;
    // Parameter axes come first, so the model is constant along a row unless the last
    // axis itself is a parameter; consecutive rows of one model make one run.
    for_each_row(box, [&](const Extent& index) {
        for (std::size_t k = 0; k < last; ++k) {
            if (axes_[k].parameter >= 0) values[static_cast<std::size_t>(axes_[k].parameter)] = axes_[k].samples[box.start[k] + index[k]];
        }
        for (std::uint64_t j = 0; j < (axes_[last].parameter >= 0 ? row : 1); ++j) {
            if (axes_[last].parameter >= 0) values[static_cast<std::size_t>(axes_[last].parameter)] = axes_[last].samples[box.start[last] + j];
            const std::size_t n = axes_[last].parameter >= 0 ? 1 : row;
            const ModelMatrices m = ModelMatrices::of(job_.model_at(values));
            if (!out.empty() && out.back().first + out.back().count == p && out.back().matrices == m) {
                out.back().count += n;
            } else {
                out.push_back({p, n, m});
            }
            p += n;
        }
    });
}

}  // namespace superball
