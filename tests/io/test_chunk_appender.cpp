// The writer of compressed tiles (io/partial_file.hpp, ChunkAppender): alone, tiles follow
// one another from the file's end as they come; one of several writers places tiles only in
// the file space granted to it, whole (a range's end too short for the next tile stays
// unused, contiguous grants are one range), asks for what waits and a stripe ahead, says
// when it is full, refuses to flush tiles that have no space, and every tile's bytes are in
// the file where it says.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <vector>

#include "io/partial_file.hpp"
#include "job/tiles.hpp"
#include "../temp_dir.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;
using test_support::TempDir;

// A batch of tiles first, first + 1, ...: tile t's stored counts are `sizes[i]` bytes of
// value t % 251, its outcomes one byte more of the same value.
TileBatch batch_of(std::uint64_t first, const std::vector<std::uint64_t>& sizes)
{
    TileBatch b;
    for (std::size_t i = 0; i < sizes.size(); ++i) {
        const std::uint64_t t = first + i;
        b.entries.insert(b.entries.end(), {t, t * 7 + 1, sizes[i], 1});
        b.data.insert(b.data.end(), sizes[i] + 1, static_cast<std::byte>(t % 251));
    }
    return b;
}

// Each written tile's bytes read back from the file where the appender says they lie.
void expect_in_file(const fs::path& path, const std::vector<AppendedTile>& tiles)
{
    std::ifstream in(path, std::ios::binary);
    for (const AppendedTile& t : tiles) {
        EXPECT_EQ(t.checksum, t.tile * 7 + 1);
        std::vector<char> got(t.stored.counts_bytes + t.stored.outcomes_bytes);
        in.seekg(static_cast<std::streamoff>(t.stored.address));
        in.read(got.data(), static_cast<std::streamsize>(got.size()));
        ASSERT_TRUE(in) << "tile " << t.tile << " beyond the file's end";
        for (const char c : got) ASSERT_EQ(static_cast<unsigned char>(c), t.tile % 251) << "tile " << t.tile;
    }
}

struct Scratch {
    TempDir dir{"superball-appender"};
    fs::path path = dir / "partial";
    Scratch() { std::ofstream(path, std::ios::binary) << std::string(100, 'h'); }  // the file's own objects
    PartialFile open() const { return PartialFile(path, Tiling({64}, {8}), PartialLayout{}); }
};

TEST(ChunkAppender, AloneAppendsFromTheEndAsTilesCome)
{
    const Scratch s;
    PartialFile file = s.open();
    ChunkAppender a(file, 100, 1 << 20);
    EXPECT_EQ(a.wanted(1000), 0u);
    a.add(batch_of(0, {10, 20}));
    a.add(batch_of(2, {30}));
    const std::vector<AppendedTile> w = a.flush();
    ASSERT_EQ(w.size(), 3u);
    EXPECT_EQ(w[0].stored.address, 100u);
    EXPECT_EQ(w[1].stored.address, 111u);
    EXPECT_EQ(w[2].stored.address, 132u);
    EXPECT_FALSE(a.holding());
    expect_in_file(s.path, w);
}

TEST(ChunkAppender, OneOfSeveralPlacesTilesOnlyInItsSpaceWhole)
{
    const Scratch s;
    PartialFile file = s.open();
    ChunkAppender a(file, ChunkAppender::Granted{64}, 1 << 20);
    a.add(batch_of(0, {9}));
    EXPECT_TRUE(a.holding());
    EXPECT_EQ(a.wanted(), 10u + 64u) << "what waits and a stripe ahead";
    EXPECT_THROW(a.flush(), std::logic_error) << "tiles without space cannot be flushed";
    // Two contiguous grants are one range of 110 bytes at 4096: tile 0, then tiles 1 and 2
    // (40 and 30 bytes); its last 30 bytes are too short for tile 3 (50), which waits.
    a.grant(4096, 75);
    a.grant(4171, 35);
    a.add(batch_of(1, {39, 29, 49}));
    EXPECT_EQ(a.wanted(), 50u + 64u) << "the range's end given up, tile 3 and a stripe ahead";
    a.grant(8192, a.wanted());
    a.add(batch_of(4, {9}));
    EXPECT_EQ(a.wanted(), 10u) << "it keeps a stripe ahead: 54 bytes held";
    const std::vector<AppendedTile> w = a.flush();
    ASSERT_EQ(w.size(), 5u);
    EXPECT_EQ(w[0].stored.address, 4096u);
    EXPECT_EQ(w[1].stored.address, 4106u) << "across the two grants";
    EXPECT_EQ(w[2].stored.address, 4146u);
    EXPECT_EQ(w[3].stored.address, 8192u) << "the end of the first range stays unused, no tile split";
    EXPECT_EQ(w[4].stored.address, 8242u);
    EXPECT_LE(w[2].stored.end(), 4206u);
    EXPECT_FALSE(a.holding());
    expect_in_file(s.path, w);
}

TEST(ChunkAppender, FullWhenMoreWaitsForSpaceThanABuffer)
{
    const Scratch s;
    PartialFile file = s.open();
    ChunkAppender a(file, ChunkAppender::Granted{0}, 100);
    a.add(batch_of(0, {49}));
    EXPECT_FALSE(a.full());
    a.add(batch_of(1, {59}));
    EXPECT_TRUE(a.full()) << "110 bytes wait, the buffer holds 100";
    a.grant(1000, a.wanted());
    EXPECT_FALSE(a.full());
    // Tiles are written once a write is started: written() starts one when none is in
    // flight; flush() waits for all.
    std::vector<AppendedTile> w = a.written();
    for (const AppendedTile& t : a.flush()) w.push_back(t);
    ASSERT_EQ(w.size(), 2u);
    expect_in_file(s.path, w);
}

}  // namespace
}  // namespace superball
