// tile_checksum: its values are part of the file format (a resume compares them with the
// checksums of files written earlier), so the fast four-lane loop must compute exactly the
// stream definition below, for every length and phase.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <span>
#include <vector>

#include "io/result_file.hpp"

namespace {

using superball::tile_checksum;

// The definition, one word at a time: word j of the stream (counts two to a word, a lone
// last count alone; then outcomes eight to a word, the last few alone) goes to lane j mod 4.
std::uint64_t definition(std::uint64_t tile, std::span<const std::uint32_t> counts, std::span<const std::uint8_t> outcomes)
{
    constexpr std::uint64_t k = 0x9E3779B97F4A7C15ull;
    std::uint64_t lane[4] = {tile, counts.size(), outcomes.size(), 0x243F6A8885A308D3ull};
    std::size_t w = 0;
    const auto mix = [&](std::uint64_t word) {
        std::uint64_t& h = lane[w++ % 4];
        h = (h ^ word) * k;
        h ^= h >> 29;
    };
    std::size_t i = 0;
    for (; i + 2 <= counts.size(); i += 2) mix(counts[i] | std::uint64_t{counts[i + 1]} << 32);
    if (i < counts.size()) mix(counts[i]);
    for (i = 0; i + 8 <= outcomes.size(); i += 8) {
        std::uint64_t word;
        std::memcpy(&word, outcomes.data() + i, sizeof word);
        mix(word);
    }
    for (; i < outcomes.size(); ++i) mix(outcomes[i]);
    std::uint64_t h = 0;
    for (const std::uint64_t l : lane) {
        h = (h ^ l) * k;
        h ^= h >> 29;
    }
    return h;
}

struct Tile {
    std::vector<std::uint32_t> counts;
    std::vector<std::uint8_t> outcomes;
};

Tile random_tile(std::size_t n, std::size_t m, std::mt19937_64& rng)
{
    Tile t{std::vector<std::uint32_t>(n), std::vector<std::uint8_t>(m)};
    for (auto& c : t.counts) c = static_cast<std::uint32_t>(rng());
    for (auto& o : t.outcomes) o = static_cast<std::uint8_t>(rng());
    return t;
}

}  // namespace

// Values of the files written so far; a change here makes every existing file unresumable.
TEST(TileChecksum, PinnedValues)
{
    std::vector<std::uint32_t> counts(1001);
    std::vector<std::uint8_t> outcomes(1003);
    for (std::size_t i = 0; i < counts.size(); ++i) counts[i] = static_cast<std::uint32_t>(i * i % 1001);
    for (std::size_t i = 0; i < outcomes.size(); ++i) outcomes[i] = static_cast<std::uint8_t>(i % 5);
    EXPECT_EQ(tile_checksum(7, counts, outcomes), 0x138fcaff1ce22820ull);
    EXPECT_EQ(tile_checksum(0, {}, {}), 0xf7e27bed97b0321eull);
}

// Every length of counts and outcomes up to a few blocks: every phase of the four lanes
// where the counts end and the outcomes begin, and every tail.
TEST(TileChecksum, EqualsTheDefinitionForEveryLengthAndPhase)
{
    std::mt19937_64 rng(2026);
    for (std::size_t n = 0; n <= 40; ++n) {
        for (std::size_t m = 0; m <= 80; ++m) {
            const Tile t = random_tile(n, m, rng);
            ASSERT_EQ(tile_checksum(n * 100 + m, t.counts, t.outcomes), definition(n * 100 + m, t.counts, t.outcomes))
                << n << " counts, " << m << " outcomes";
        }
    }
}

TEST(TileChecksum, EveryChangedValueChangesIt)
{
    std::mt19937_64 rng(7);
    Tile t = random_tile(257, 259, rng);
    const std::uint64_t sum = tile_checksum(3, t.counts, t.outcomes);
    for (std::size_t i = 0; i < t.counts.size(); ++i) {
        const std::uint32_t kept = t.counts[i];
        t.counts[i] ^= 1u << (i % 32);
        EXPECT_NE(tile_checksum(3, t.counts, t.outcomes), sum) << "count " << i;
        t.counts[i] = kept;
    }
    for (std::size_t i = 0; i < t.outcomes.size(); ++i) {
        const std::uint8_t kept = t.outcomes[i];
        t.outcomes[i] = static_cast<std::uint8_t>(kept + 1);
        EXPECT_NE(tile_checksum(3, t.counts, t.outcomes), sum) << "outcome " << i;
        t.outcomes[i] = kept;
    }
    // So does the tile number.
    EXPECT_NE(tile_checksum(4, t.counts, t.outcomes), sum);
    EXPECT_EQ(tile_checksum(3, t.counts, t.outcomes), sum);
}
