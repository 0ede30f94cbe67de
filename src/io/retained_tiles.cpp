#include "retained_tiles.hpp"

#include <algorithm>

namespace superball {

RetainedTiles::RetainedTiles(std::uint64_t counts_chunk, std::uint64_t outcomes_chunk, std::uint64_t budget)
    : counts_chunk_(counts_chunk), outcomes_chunk_(outcomes_chunk), budget_(budget)
{
}

bool RetainedTiles::add(std::uint64_t tile, std::span<const std::byte> counts, std::span<const std::byte> outcomes)
{
    const std::uint64_t n = counts_chunk_ + outcomes_chunk_;
    if (full_ || used_ + n > budget_ || counts.size() != counts_chunk_ || outcomes.size() != outcomes_chunk_) {
        full_ = true;
        return false;
    }
    if (blocks_.empty() || blocks_.back().capacity() - blocks_.back().size() < n) {
        // 4 MiB blocks (or one tile), not one allocation per tile.
        const std::uint64_t tiles_per_block = std::max<std::uint64_t>(1, (std::uint64_t{4} << 20) / n);
        blocks_.emplace_back();
        blocks_.back().reserve(std::min(tiles_per_block * n, std::max(n, budget_ - used_)));
    }
    std::vector<std::byte>& b = blocks_.back();
    const std::byte* const at = b.data() + b.size();
    b.insert(b.end(), counts.begin(), counts.end());
    b.insert(b.end(), outcomes.begin(), outcomes.end());
    where_[tile] = at;
    used_ += n;
    return true;
}

const std::byte* RetainedTiles::find(std::uint64_t tile) const
{
    const auto it = where_.find(tile);
    return it == where_.end() ? nullptr : it->second;
}

std::vector<std::uint64_t> RetainedTiles::tiles() const
{
    std::vector<std::uint64_t> out;
    out.reserve(where_.size());
    for (const auto& [tile, at] : where_) out.push_back(tile);
    return out;
}

}  // namespace superball
