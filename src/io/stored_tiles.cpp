#include "stored_tiles.hpp"

#include <xxhash.h>

namespace superball {

std::uint64_t tile_checksum(std::uint64_t tile, std::span<const std::byte> counts_chunk,
                            std::span<const std::byte> outcomes_chunk)
{
    const XXH64_hash_t first = XXH3_64bits_withSeed(counts_chunk.data(), counts_chunk.size(), tile);
    return XXH3_64bits_withSeed(outcomes_chunk.data(), outcomes_chunk.size(), first);
}

}  // namespace superball
