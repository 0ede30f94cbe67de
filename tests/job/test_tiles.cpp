// The order in which a run hands out its tiles (job/tiles.hpp, handout_order).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/tiles.hpp"

namespace superball {
namespace {

std::vector<ListedTile> iota(std::uint64_t n)
{
    std::vector<ListedTile> v(n);
    std::iota(v.begin(), v.end(), ListedTile{0});
    return v;
}

TEST(HandoutOrder, NotInterleavedKeepsTheGridOrder)
{
    const std::vector<ListedTile> pending = iota(1000);
    EXPECT_EQ(handout_order(pending, 8, false), pending);
}

TEST(HandoutOrder, ManyRanksTakeWholeGranulesInBitReversedOrder)
{
    // 8 granules of 4 tiles: granules 0 4 2 6 1 5 3 7, each in its own order.
    const std::vector<ListedTile> order = handout_order(iota(32), 4, true);
    const std::vector<ListedTile> granules{0, 4, 2, 6, 1, 5, 3, 7};
    ASSERT_EQ(order.size(), 32u);
    for (std::size_t i = 0; i < order.size(); ++i) {
        EXPECT_EQ(order[i], granules[i / 4] * 4 + i % 4) << "position " << i;
    }
}

TEST(HandoutOrder, AnyPrefixOfAPowerOfTwoGranulesSpreadsOverTheGrid)
{
    // 1024 granules: the first 2^k granules handed out fall one in each 1/2^k of the grid.
    const std::uint64_t granule = 16, granules = 1024;
    const std::vector<ListedTile> order = handout_order(iota(granule * granules), granule, true);
    for (std::uint64_t k = 1; k <= granules; k *= 2) {
        std::vector<int> hits(k, 0);
        for (std::uint64_t g = 0; g < k; ++g) ++hits[order[g * granule] / granule / (granules / k)];
        EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; })) << "first " << k << " granules";
    }
}

TEST(HandoutOrder, EveryTileOnceAndIncompleteGranulesLast)
{
    // A resume: tiles done here and there leave some granules incomplete; the grid's last
    // granule is short too (103 tiles, granule 8).
    std::vector<ListedTile> pending;
    for (std::uint64_t t = 0; t < 103; ++t) {
        if (t != 17 && t != 18 && t != 60) pending.push_back(t);
    }
    const std::vector<ListedTile> order = handout_order(pending, 8, true);
    std::vector<ListedTile> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, pending);
    // Whole granules first, each a run of 8 consecutive tiles starting on a multiple of 8
    // positions; then granules 2 (16, 19..23), 7 (56..59, 61..63) and 12 (96..102).
    const std::size_t whole = order.size() - (6 + 7 + 7);
    ASSERT_EQ(whole % 8, 0u);
    for (std::size_t i = 0; i < whole; i += 8) {
        EXPECT_EQ(order[i] % 8, 0u) << "position " << i;
        for (std::size_t j = 1; j < 8; ++j) EXPECT_EQ(order[i + j], order[i] + j);
    }
    const std::vector<ListedTile> tail(order.begin() + static_cast<std::ptrdiff_t>(whole), order.end());
    const std::vector<ListedTile> expected{16, 19, 20, 21, 22, 23, 56, 57, 58, 59, 61, 62, 63, 96, 97, 98, 99, 100, 101, 102};
    EXPECT_EQ(tail, expected);
}

// The order as job/tiles.hpp states it, built the plain way: runs of a granule's pending
// tiles, whole ones by bit-reversed granule number, then the incomplete ones in grid order.
std::vector<ListedTile> order_as_stated(const std::vector<ListedTile>& pending, std::uint64_t granule)
{
    std::vector<std::vector<ListedTile>> runs;
    for (const std::uint64_t t : pending) {
        if (runs.empty() || runs.back().back() / granule != t / granule) runs.emplace_back();
        runs.back().push_back(t);
    }
    const std::uint64_t last = pending.back() / granule;
    int bits = 0;
    while ((std::uint64_t{1} << bits) <= last) ++bits;
    const auto reversed = [bits](std::uint64_t g) {
        std::uint64_t r = 0;
        for (int b = 0; b < bits; ++b) r = (r << 1) | ((g >> b) & 1u);
        return r;
    };
    const auto whole = [granule](const std::vector<ListedTile>& r) { return r.size() == granule; };
    std::stable_sort(runs.begin(), runs.end(), [&](const auto& a, const auto& b) {
        if (whole(a) != whole(b)) return whole(a);
        return whole(a) && reversed(a.front() / granule) < reversed(b.front() / granule);
    });
    std::vector<ListedTile> order;
    for (const auto& r : runs) order.insert(order.end(), r.begin(), r.end());
    return order;
}

TEST(HandoutOrder, AsStatedForRandomResumesAndGranules)
{
    // Resumes with a random fifth of the tiles done, grids that are and are not a power of
    // two of granules, granules of 1 (compressed files) to 16.
    std::mt19937_64 random(32);
    for (const std::uint64_t granule : {1u, 2u, 3u, 8u, 16u}) {
        for (const std::uint64_t tiles : {1u, 7u, 64u, 1000u, 4099u}) {
            std::vector<ListedTile> pending;
            for (std::uint64_t t = 0; t < tiles; ++t) {
                if (random() % 5 != 0) pending.push_back(t);
            }
            if (pending.empty()) continue;
            EXPECT_EQ(handout_order(pending, granule, true), order_as_stated(pending, granule))
                << tiles << " tiles, granule " << granule;
        }
    }
}

// Tiles are the result's chunks: large on a workstation (the file's size), many per rank
// on a cluster (the end of the schedule).
TEST(DefaultTilePoints, LargeChunksOnFewRanksManyTilesOnMany)
{
    constexpr std::uint64_t k = 1024;
    // The 8192^2 benchmark slice at 1 and 2 ranks: the largest tiles, 2^18 points.
    EXPECT_EQ(default_tile_points(8192 * 8192, 1), 256 * k);
    EXPECT_EQ(default_tile_points(8192 * 8192, 2), 256 * k);
    // The 1024^2 quickstart slice: 2^17 points, 8 tiles at 1 or 2 ranks (4 tiles a rank at
    // least), not 16 a rank of 2^15.
    EXPECT_EQ(default_tile_points(1024 * 1024, 1), 128 * k);
    EXPECT_EQ(default_tile_points(1024 * 1024, 2), 128 * k);
    EXPECT_EQ(default_tile_points(1024 * 1024, 16), 16 * k);  // 4 tiles a rank
    // Small grids: 1024 points at least.
    EXPECT_EQ(default_tile_points(64 * 64, 2), k);
    EXPECT_EQ(default_tile_points(10, 1), k);
    // From 64 ranks: 512 tiles a rank, at most 2^16 points.
    EXPECT_EQ(default_tile_points(std::uint64_t{4096} * 2048 * 2048, 4096), 8 * k);
    EXPECT_EQ(default_tile_points(std::uint64_t{4096} * 2048 * 2048, 1024), 32 * k);
    EXPECT_EQ(default_tile_points(std::uint64_t{4096} * 4096 * 4096, 1024), 64 * k);
    EXPECT_EQ(default_tile_points(8192 * 8192, 64), 2 * k);
}

TEST(HandoutOrder, NothingPending)
{
    EXPECT_TRUE(handout_order({}, 8, true).empty());
}

// The hand-out list holds four-byte tile numbers: a job that would make more tiles than a
// run takes is refused before anything is made, naming the setting to raise.
TEST(DefaultTiling, MoreTilesThanARunTakesIsRefused)
{
    const auto job = [](const std::string& tile_points) {
        return parse_job("[model]\ne = 0.9\nalpha = 0.9\n[grid]\ncoordinates = \"canonical\"\n"
                         "xi = { min = 0, max = 1, n = 65536 }\nU = { min = -3, max = 0, n = 32768 }\nW = 0\n"
                         "[run]\nmax_bounces = 10\ntile_points = " + tile_points + "\n",
                         "test.toml");
    };
    // 2^31 points: tiles of 2 points make 2^30, the most a run takes; of 1, twice that.
    EXPECT_EQ(default_tiling(job("2"), 1).tiles(), max_run_tiles);
    try {
        default_tiling(job("1"), 1);
        FAIL() << "2^31 tiles accepted";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("2147483648 tiles"), std::string::npos) << m;
        EXPECT_NE(m.find("[run] tile_points = 4 or more"), std::string::npos) << m;
    }
}

}  // namespace
}  // namespace superball
