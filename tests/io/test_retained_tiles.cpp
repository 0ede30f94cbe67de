// Tiles kept in memory for the closing pass (io/retained_tiles.hpp).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/retained_tiles.hpp"

namespace superball {
namespace {

std::vector<std::byte> bytes(std::size_t n, int first)
{
    std::vector<std::byte> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::byte>((first + static_cast<int>(i)) & 0xff);
    return v;
}

TEST(RetainedTiles, KeepsCountsThenOutcomesOfEachTile)
{
    RetainedTiles kept(8, 4, 1000);
    EXPECT_TRUE(kept.add(7, bytes(8, 10), bytes(4, 50)));
    EXPECT_TRUE(kept.add(3, bytes(8, 20), bytes(4, 60)));
    EXPECT_EQ(kept.tiles(), (std::vector<std::uint64_t>{3, 7}));
    EXPECT_EQ(kept.bytes(), 24u);
    const std::byte* t = kept.find(7);
    ASSERT_NE(t, nullptr);
    EXPECT_EQ(std::vector<std::byte>(t, t + 8), bytes(8, 10));
    EXPECT_EQ(std::vector<std::byte>(t + 8, t + 12), bytes(4, 50));
    EXPECT_EQ(kept.find(4), nullptr);
}

TEST(RetainedTiles, StopsForGoodAtTheBudgetAndKeepsWhatItHas)
{
    // 12 bytes a tile, 40 in all: three tiles; the fourth and every later one refused.
    RetainedTiles kept(8, 4, 40);
    for (std::uint64_t t = 0; t < 3; ++t) EXPECT_TRUE(kept.add(t, bytes(8, static_cast<int>(t)), bytes(4, 100)));
    EXPECT_FALSE(kept.add(3, bytes(8, 3), bytes(4, 100)));
    EXPECT_TRUE(kept.full());
    EXPECT_FALSE(kept.add(4, bytes(8, 4), bytes(4, 100)));
    EXPECT_EQ(kept.tiles(), (std::vector<std::uint64_t>{0, 1, 2}));
    // Earlier tiles are intact whatever was refused after them.
    for (std::uint64_t t = 0; t < 3; ++t) {
        const std::byte* p = kept.find(t);
        ASSERT_NE(p, nullptr);
        EXPECT_EQ(std::vector<std::byte>(p, p + 8), bytes(8, static_cast<int>(t)));
    }
}

TEST(RetainedTiles, PointersStayValidAcrossBlocks)
{
    // Tiles of 1 MiB + 64 KiB: a few per 4 MiB block, so the store starts new blocks.
    const std::size_t c = std::size_t{1} << 20, o = std::size_t{1} << 16;
    RetainedTiles kept(c, o, std::uint64_t{64} << 20);
    std::vector<const std::byte*> at;
    for (int t = 0; t < 12; ++t) {
        ASSERT_TRUE(kept.add(static_cast<std::uint64_t>(t), bytes(c, t), bytes(o, 200 + t)));
        at.push_back(kept.find(static_cast<std::uint64_t>(t)));
    }
    for (int t = 0; t < 12; ++t) {
        EXPECT_EQ(kept.find(static_cast<std::uint64_t>(t)), at[static_cast<std::size_t>(t)]);
        EXPECT_EQ(std::vector<std::byte>(at[static_cast<std::size_t>(t)], at[static_cast<std::size_t>(t)] + c), bytes(c, t));
    }
}

TEST(RetainedTiles, RefusesChunksOfAnotherSize)
{
    RetainedTiles kept(8, 4, 1000);
    EXPECT_FALSE(kept.add(0, bytes(6, 0), bytes(4, 0)));
}

}  // namespace
}  // namespace superball
