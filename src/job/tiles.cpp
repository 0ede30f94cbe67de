#include "tiles.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace superball {

std::uint64_t Box::points() const
{
    std::uint64_t n = 1;
    for (const std::uint64_t c : count) n *= c;
    return n;
}

Box intersect(const Box& a, const Box& b)
{
    Box r{Extent(a.start.size()), Extent(a.start.size())};
    for (std::size_t d = 0; d < a.start.size(); ++d) {
        const std::uint64_t lo = std::max(a.start[d], b.start[d]);
        const std::uint64_t hi = std::min(a.start[d] + a.count[d], b.start[d] + b.count[d]);
        r.start[d] = lo;
        r.count[d] = hi > lo ? hi - lo : 0;
    }
    return r;
}

void copy_box(const Box& part, const std::byte* src, const Extent& src_start, const Extent& src_shape, std::byte* dst,
              const Extent& dst_start, const Extent& dst_shape, std::size_t bytes)
{
    const std::size_t dims = part.start.size();
    if (part.points() == 0) return;
    const std::size_t row = part.count[dims - 1] * bytes;
    Extent at(dims, 0);  // index within part of the current row (last axis 0)
    for (;;) {
        std::uint64_t s = 0, t = 0;
        for (std::size_t d = 0; d < dims; ++d) {
            s = s * src_shape[d] + (part.start[d] + at[d] - src_start[d]);
            t = t * dst_shape[d] + (part.start[d] + at[d] - dst_start[d]);
        }
        std::memcpy(dst + t * bytes, src + s * bytes, row);
        std::size_t d = dims - 1;
        while (d-- > 0) {
            if (++at[d] < part.count[d]) break;
            at[d] = 0;
        }
        if (d == static_cast<std::size_t>(-1)) return;
    }
}

Tiling::Tiling(Extent shape, Extent tile) : shape_(std::move(shape)), tile_(std::move(tile))
{
    if (shape_.empty() || shape_.size() != tile_.size()) throw std::invalid_argument("tiling: rank mismatch");
    tiles_ = 1;
    for (std::size_t i = 0; i < shape_.size(); ++i) {
        if (shape_[i] == 0 || tile_[i] == 0) throw std::invalid_argument("tiling: empty axis");
        tile_[i] = std::min(tile_[i], shape_[i]);
        tiles_per_axis_.push_back((shape_[i] + tile_[i] - 1) / tile_[i]);
        tiles_ *= tiles_per_axis_.back();
    }
}

std::uint64_t Tiling::points() const
{
    std::uint64_t n = 1;
    for (const std::uint64_t s : shape_) n *= s;
    return n;
}

Box Tiling::box(std::uint64_t t) const
{
    Box b{Extent(shape_.size()), Extent(shape_.size())};
    for (std::size_t k = shape_.size(); k-- > 0;) {
        const std::uint64_t j = t % tiles_per_axis_[k];
        t /= tiles_per_axis_[k];
        b.start[k] = j * tile_[k];
        b.count[k] = std::min(tile_[k], shape_[k] - b.start[k]);
    }
    return b;
}

std::uint64_t Tiling::tile_points() const
{
    std::uint64_t n = 1;
    for (const std::uint64_t s : tile_) n *= s;
    return n;
}

Extent default_tile_shape(const Extent& shape, std::uint64_t target_points)
{
    Extent tile = shape;
    auto points = [&] {
        std::uint64_t n = 1;
        for (const std::uint64_t s : tile) n *= s;
        return n;
    };
    while (points() > target_points) {
        auto longest = std::max_element(tile.begin(), tile.end());
        if (*longest == 1) break;
        *longest = (*longest + 1) / 2;
    }
    return tile;
}

std::uint64_t default_tile_points(std::uint64_t grid_points, int ranks)
{
    const auto r = static_cast<std::uint64_t>(std::max(ranks, 1));
    if (r >= interleave_ranks_default) {
        return std::clamp<std::uint64_t>(grid_points / (512 * r), 1024, std::uint64_t{1} << 16);
    }
    // At least 4 tiles per rank, and tiles of 2^17 points where that leaves so many.
    const std::uint64_t floor = std::clamp<std::uint64_t>(grid_points / (4 * r), 1024, std::uint64_t{1} << 17);
    return std::clamp<std::uint64_t>(grid_points / (16 * r), floor, std::uint64_t{1} << 18);
}

std::vector<std::uint64_t> handout_order(const std::vector<std::uint64_t>& pending, std::uint64_t granule, bool interleave)
{
    if (!interleave || granule == 0 || pending.empty()) return pending;
    // Runs of pending tiles by granule number (t / granule), in pending's ascending order.
    struct Run {
        std::uint64_t granule, begin, end;  // [begin, end) positions in pending
    };
    std::vector<Run> runs;
    for (std::uint64_t i = 0; i < pending.size(); ++i) {
        const std::uint64_t g = pending[i] / granule;
        if (runs.empty() || runs.back().granule != g) runs.push_back({g, i, i});
        runs.back().end = i + 1;
    }
    int bits = 0;
    while ((std::uint64_t{1} << bits) <= runs.back().granule) ++bits;
    const auto reversed = [bits](std::uint64_t g) {
        std::uint64_t r = 0;
        for (int b = 0; b < bits; ++b) r |= ((g >> b) & 1u) << (bits - 1 - b);
        return r;
    };
    // Whole granules in bit-reversed order, then the incomplete ones (a resume's, the
    // grid's last) in grid order, so that the whole ones stay on multiples of `granule`.
    const auto whole = [granule](const Run& r) { return r.end - r.begin == granule; };
    std::stable_sort(runs.begin(), runs.end(), [&](const Run& a, const Run& b) {
        if (whole(a) != whole(b)) return whole(a);
        return whole(a) ? reversed(a.granule) < reversed(b.granule) : a.granule < b.granule;
    });
    std::vector<std::uint64_t> order;
    order.reserve(pending.size());
    for (const Run& r : runs) order.insert(order.end(), pending.begin() + static_cast<std::ptrdiff_t>(r.begin),
                                           pending.begin() + static_cast<std::ptrdiff_t>(r.end));
    return order;
}

}  // namespace superball
