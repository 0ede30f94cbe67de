#include "tiles.hpp"

#include <algorithm>
#include <stdexcept>

namespace superball {

std::uint64_t Box::points() const
{
    std::uint64_t n = 1;
    for (const std::uint64_t c : count) n *= c;
    return n;
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
    const std::uint64_t per_rank_share = grid_points / (64 * static_cast<std::uint64_t>(std::max(ranks, 1)));
    return std::clamp<std::uint64_t>(per_rank_share, 1024, 16384);
}

}  // namespace superball
