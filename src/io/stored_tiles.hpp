// What a partial file records of each tile (io/partial_file.hpp): its checksum and, for
// compressed tiles, where its stored chunks lie. Shared by the writers and the reader
// (which needs no MPI).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace superball {

// Where a compressed tile's stored chunks lie: its counts at `address`, its outcomes
// right after them.
struct StoredChunk {
    std::uint64_t address = 0;
    std::uint64_t counts_bytes = 0;
    std::uint64_t outcomes_bytes = 0;

    std::uint64_t end() const { return address + counts_bytes + outcomes_bytes; }
};

// A compressed tile once rank 0 has written it.
struct AppendedTile {
    std::uint64_t tile = 0;
    std::uint64_t checksum = 0;
    StoredChunk stored;
};

// The checksum of a tile as the partial file stores it: XXH3-64 (xxHash, a stable format)
// of the tile's chunk of /wall_bounces then its chunk of /outcome, as stored (uncompressed:
// little-endian, a chunk's points beyond the grid's edge zero; compressed: the stored
// streams), seeded with the tile's number.
std::uint64_t tile_checksum(std::uint64_t tile, std::span<const std::byte> counts_chunk,
                            std::span<const std::byte> outcomes_chunk);

}  // namespace superball
