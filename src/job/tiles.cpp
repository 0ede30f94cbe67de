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

namespace {

// g's lowest `bits` bits in reverse order (bits <= 64).
std::uint64_t reverse_bits(std::uint64_t g, int bits)
{
    if (bits == 0) return 0;
    g = ((g >> 1) & 0x5555555555555555u) | ((g & 0x5555555555555555u) << 1);
    g = ((g >> 2) & 0x3333333333333333u) | ((g & 0x3333333333333333u) << 2);
    g = ((g >> 4) & 0x0F0F0F0F0F0F0F0Fu) | ((g & 0x0F0F0F0F0F0F0F0Fu) << 4);
    g = ((g >> 8) & 0x00FF00FF00FF00FFu) | ((g & 0x00FF00FF00FF00FFu) << 8);
    g = ((g >> 16) & 0x0000FFFF0000FFFFu) | ((g & 0x0000FFFF0000FFFFu) << 16);
    g = (g >> 32) | (g << 32);
    return g >> (64 - bits);
}

}  // namespace

std::vector<ListedTile> handout_order(std::vector<ListedTile> pending, std::uint64_t granule, bool interleave)
{
    if (!interleave || granule == 0 || pending.empty()) return pending;
    if (pending.back() >= max_run_tiles) throw std::logic_error("handout_order: a tile beyond max_run_tiles");
    // Sorted in place by a key that says where each tile goes, then turned back into the
    // tile: every rank builds this list at the start of a run, and one vector of 4 bytes a
    // tile is all it holds (4.2 million tiles: 17 MB, where runs of tiles sorted beside
    // the list held ten times that). Keys stay below 2^32: base <= 2 * max_run_tiles.
    // Whole granule g's tile g * granule + k: key reverse(g) * granule + k, below `base`;
    // a tile t of an incomplete granule: base + t, after every whole one, in grid order.
    int bits = 0;
    while ((std::uint64_t{1} << bits) <= pending.back() / granule) ++bits;
    const std::uint64_t base = (std::uint64_t{1} << bits) * granule;
    for (std::size_t i = 0; i < pending.size();) {
        // pending ascends, so a granule's pending tiles are consecutive: [i, j).
        const std::uint64_t g = pending[i] / granule;
        std::size_t j = i + 1;
        while (j < pending.size() && pending[j] / granule == g) ++j;
        const bool whole = j - i == granule;
        for (; i < j; ++i) {
            pending[i] = static_cast<ListedTile>(whole ? reverse_bits(g, bits) * granule + pending[i] % granule : base + pending[i]);
        }
    }
    std::sort(pending.begin(), pending.end());
    for (ListedTile& key : pending) {
        key = static_cast<ListedTile>(key < base ? reverse_bits(key / granule, bits) * granule + key % granule : key - base);
    }
    return pending;
}

}  // namespace superball
