#include "grid.hpp"

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
    out.clear();
    out.reserve(box.points());
    std::vector<double> coords = fixed_;
    const std::size_t d = samples_.size();
    const std::size_t last = d - 1;
    const std::vector<double>& fastest = samples_[last];
    // Odometer over every axis but the last; the last axis is the inner loop.
    Extent index(d, 0);
    for (;;) {
        for (std::size_t k = 0; k < last; ++k) coords[range_index_[k]] = samples_[k][box.start[k] + index[k]];
        for (std::uint64_t j = 0; j < box.count[last]; ++j) {
            coords[range_index_[last]] = fastest[box.start[last] + j];
            out.push_back(canonical(coords));
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
