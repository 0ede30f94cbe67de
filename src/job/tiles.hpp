// Cutting a grid into rectangular tiles. A tile is also the HDF5 chunk of the result,
// so each tile is compressed and written in one piece.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace superball {

using Extent = std::vector<std::uint64_t>;  // one entry per range axis, first axis slowest

// A finished tile, as its writer reports it: which tile, and the checksum of its data as
// stored (the resume journal keeps it; a resume checks the data against it).
struct TileReport {
    std::uint64_t tile = 0;
    std::uint64_t checksum = 0;
};

// A block of the grid: [start, start + count) along each axis.
struct Box {
    Extent start;
    Extent count;

    std::uint64_t points() const;
};

// The common part of two boxes (counts 0 along the axes where they do not meet).
Box intersect(const Box& a, const Box& b);

// Copies the values of box `part` (grid coordinates), `bytes` bytes each, from `src`, a
// row-major array over the box at `src_start` of shape `src_shape`, into `dst`, likewise;
// both boxes hold `part`. A run of the last axis at a time.
void copy_box(const Box& part, const std::byte* src, const Extent& src_start, const Extent& src_shape, std::byte* dst,
              const Extent& dst_start, const Extent& dst_shape, std::size_t bytes);

class Tiling {
public:
    // shape: grid points per axis; tile: points per axis of a full tile (clipped to shape).
    Tiling(Extent shape, Extent tile);

    const Extent& shape() const { return shape_; }
    const Extent& tile_shape() const { return tile_; }
    std::uint64_t tiles() const { return tiles_; }
    std::uint64_t points() const;

    // Tile t, row-major over the tiles; edge tiles are smaller.
    Box box(std::uint64_t t) const;
    // Points of a full tile (an HDF5 chunk holds that many whatever the tile's box).
    std::uint64_t tile_points() const;
    // Calls f(t) for every tile meeting box `b` (within the grid), in ascending order.
    template <class F>
    void for_each_meeting(const Box& b, F&& f) const;

private:
    Extent shape_;
    Extent tile_;
    Extent tiles_per_axis_;
    std::uint64_t tiles_ = 0;
};

template <class F>
void Tiling::for_each_meeting(const Box& b, F&& f) const
{
    const std::size_t dims = b.start.size();
    Extent lo(dims), hi(dims), at(dims);
    for (std::size_t d = 0; d < dims; ++d) {
        if (b.count[d] == 0) return;
        lo[d] = b.start[d] / tile_[d];
        hi[d] = (b.start[d] + b.count[d] - 1) / tile_[d];
        at[d] = lo[d];
    }
    for (;;) {
        std::uint64_t t = 0;
        for (std::size_t d = 0; d < dims; ++d) t = t * tiles_per_axis_[d] + at[d];
        f(t);
        std::size_t d = dims;
        while (d-- > 0) {
            if (++at[d] <= hi[d]) break;
            at[d] = lo[d];
        }
        if (d == static_cast<std::size_t>(-1)) return;
    }
}

// A tile shape of about `target_points` points: the grid is halved along its currently
// longest tile side until the tile is small enough, which keeps tiles near-cubic and
// their sides powers-of-two fractions of the grid.
Extent default_tile_shape(const Extent& shape, std::uint64_t target_points);

// Target points per tile for `ranks` ranks. A tile is also a chunk of the result,
// compressed on its own: big enough (up to 2^18 points, 512 KiB of 16-bit counts) that a
// deflate stream's fixed costs (its header and code tables, an index entry: about 150
// bytes a chunk) stay small against what it holds and readers decompress few chunks;
// small enough that the dynamic schedule can balance very unequal costs.
// - Below interleave_ranks_default (64) ranks: 16 tiles per rank, but never below 2^17
//   points while that leaves 4 tiles per rank (the 1024^2 quickstart slice on 2 ranks: 8
//   tiles of 2^17 points, a 53 KB result; in 32 tiles of 2^15, 56 KB; its compute phase
//   takes 10 ms either way), and never below 1024 points.
// - From 64 ranks on: 512 tiles per rank, 1024 to 2^16 points. The end of a run on
//   thousands of ranks waits for its costliest tile: the corner zoom of jobs/cluster at
//   4096 simulated ranks counted at 0.874 of the ideal in tiles of 2^16 points and 0.967
//   in tiles of 2^14 (tests/scale/simulate.sh); its data compress 4 times only, so a chunk's
//   fixed bytes cost it under 1 %. Not fewer: with 256 tiles per rank sweep_e_alpha's
//   costliest tiles (7.4 s) made its end to end 0.894, 0.903 with 512 (docs/decisions.md).
std::uint64_t default_tile_points(std::uint64_t grid_points, int ranks);

// A tile's number in the hand-out list every rank holds through a run (run/schedule.hpp):
// four bytes, not eight (at 4.2 million tiles, 17 MB a rank instead of 34), which holds the
// number of any tile of a run of at most max_run_tiles (handout_order's keys, up to three
// times the largest tile, included).
using ListedTile = std::uint32_t;
inline constexpr std::uint64_t max_run_tiles = std::uint64_t{1} << 30;

// From this many ranks on, a run hands out its tiles interleaved (handout_order).
inline constexpr int interleave_ranks_default = 64;

// The order in which a run hands out its `pending` tiles (ascending tile numbers); the
// schedule cuts this sequence into blocks of consecutive entries, in multiples of
// `granule` entries where it can (one alignment unit of the file's data).
// Not interleaved (runs on fewer than interleave_ranks_default ranks): `pending` as it is,
// so a rank's block is one run of consecutive tiles (one write per dataset).
// Interleaved: whole granules (runs of `granule` consecutive tiles, each one aligned
// write) in bit-reversed order of their number, any incomplete granule last. Costs
// cluster in the grid (a region of trapped launches costs thousands of times an escaping
// one), and guided self-scheduling sizes blocks by their tiles, not their cost: in grid
// order the first, largest blocks of a costly region hold many times a rank's share while
// the other ranks run through the cheap regions and wait (at 4096 simulated ranks, 3.4 s
// each in the first 3 s of a 40 s run; interleaved, 0.2 s: tests/scale). Bit-reversed, any
// 2^k consecutive granules sample the whole grid evenly, so a block's cost follows its
// size. Results never depend on the order.
std::vector<ListedTile> handout_order(std::vector<ListedTile> pending, std::uint64_t granule, bool interleave);

}  // namespace superball
