// tile_checksum: its values are part of the partial file's format (a resume compares them
// with the checksums of tiles written by an earlier run), so they are pinned here; and it
// must notice any change of the stored bytes of a tile.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "io/partial_file.hpp"

namespace {

using superball::tile_checksum;

std::vector<std::byte> bytes(std::size_t n, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::vector<std::byte> v(n);
    for (auto& b : v) b = static_cast<std::byte>(rng() & 0xff);
    return v;
}

TEST(TileChecksum, PinnedValues)
{
    // XXH3-64 (xxHash >= 0.8.0, whose output is stable): a change here breaks every resume
    // of a partial file written before it.
    const std::vector<std::byte> counts = bytes(2048, 1), outcomes = bytes(1024, 2);
    // Values of XXH3_64bits_withSeed(outcomes, XXH3_64bits_withSeed(counts, tile)) computed
    // with xxHash 0.8.1 directly.
    EXPECT_EQ(tile_checksum(0, counts, outcomes), 0x5f26244fffae9c70ull);
    EXPECT_EQ(tile_checksum(7, {}, {}), 0x5f0fa86095c632bdull);
}

TEST(TileChecksum, EveryByteCounts)
{
    std::vector<std::byte> counts = bytes(512, 3), outcomes = bytes(256, 4);
    const std::uint64_t base = tile_checksum(5, counts, outcomes);
    for (std::size_t i = 0; i < counts.size(); ++i) {
        counts[i] ^= std::byte{1};
        EXPECT_NE(tile_checksum(5, counts, outcomes), base) << "count byte " << i;
        counts[i] ^= std::byte{1};
    }
    for (std::size_t i = 0; i < outcomes.size(); ++i) {
        outcomes[i] ^= std::byte{0x80};
        EXPECT_NE(tile_checksum(5, counts, outcomes), base) << "outcome byte " << i;
        outcomes[i] ^= std::byte{0x80};
    }
    EXPECT_EQ(tile_checksum(5, counts, outcomes), base);
}

TEST(TileChecksum, TileNumberAndBoundaryCount)
{
    const std::vector<std::byte> counts = bytes(64, 5), outcomes = bytes(32, 6);
    EXPECT_NE(tile_checksum(1, counts, outcomes), tile_checksum(2, counts, outcomes));
    // The same bytes split differently between the two datasets are another tile.
    std::vector<std::byte> all(counts);
    all.insert(all.end(), outcomes.begin(), outcomes.end());
    const std::span<const std::byte> a(all);
    EXPECT_NE(tile_checksum(1, a.first(64), a.subspan(64)), tile_checksum(1, a.first(65), a.subspan(65)));
}

}  // namespace
