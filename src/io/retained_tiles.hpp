// Tiles a rank keeps in memory after writing them, for the closing pass (final_result.hpp):
// the ranks that computed them send them to the ranks that compress them, instead of every
// rank reading its share back from the partial file. On a shared file system that read is
// the whole raw data again: at 4096 simulated ranks 50-100 GB, 3-5 s of a 70 s run
// (tests/scale); over the network it is a fraction of a second.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <vector>

namespace superball {

class RetainedTiles {
public:
    // Tiles of `counts_chunk` bytes of counts and `outcomes_chunk` bytes of outcomes (their
    // chunks as the partial file stores them), up to `budget` bytes in all.
    RetainedTiles(std::uint64_t counts_chunk, std::uint64_t outcomes_chunk, std::uint64_t budget);

    // Keeps a copy of the tile's chunks; false (nothing kept) when that would pass the
    // budget: that tile, and any tile after it, is read back from the file instead.
    bool add(std::uint64_t tile, std::span<const std::byte> counts, std::span<const std::byte> outcomes);

    // The tile's chunk of counts, followed by its chunk of outcomes; nullptr if not kept.
    const std::byte* find(std::uint64_t tile) const;
    // The tiles kept, ascending.
    std::vector<std::uint64_t> tiles() const;
    std::uint64_t counts_chunk() const { return counts_chunk_; }
    std::uint64_t bytes() const { return used_; }
    bool full() const { return full_; }

private:
    std::uint64_t counts_chunk_, outcomes_chunk_, budget_;
    std::uint64_t used_ = 0;
    bool full_ = false;
    // Blocks reserved whole and never grown past their capacity, so pointers into them stay
    // valid (moving a vector keeps its storage).
    std::vector<std::vector<std::byte>> blocks_;
    std::map<std::uint64_t, const std::byte*> where_;
};

}  // namespace superball
