// Rank 0's journal (io/partial_file.hpp Journal): a tile's checksum and place reach the
// partial file when it is recorded, its done flag only at a checkpoint (the flags vouch for
// what was written before them), and read_journal gives back the record of tiles spread
// over more than one of its windows.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/partial_file.hpp"
#include "io/posix_file.hpp"
#include "job/tiles.hpp"
#include "../temp_dir.hpp"
#include "journal_file.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

using test_support::journal_file;
using test_support::TempDir;

constexpr std::uint64_t tiles = 300000;  // more than four of read_journal's windows

std::vector<std::uint8_t> flags_in(const fs::path& path, const PartialLayout& l)
{
    std::vector<std::uint8_t> done(tiles);
    PosixFile(path, false).read_at(l.done_at, done.data(), done.size());
    return done;
}

const std::vector<std::uint64_t> spread{0, 1, 2, 5, 65535, 65536, 70000, 200001, 299999};

AppendedTile appended(std::uint64_t t) { return {t, 1000 + 3 * t, {40 * t + 7, 11 + t % 5, 3 + t % 7}}; }

TEST(Journal, PlacesAndChecksumsAtOnceDoneFlagsAtTheCheckpoint)
{
    const TempDir dir("superball-journal");
    const fs::path path = dir / "partial.h5";
    const PartialLayout layout = journal_file(path, tiles, true);
    PartialFile file(path, Tiling({tiles}, {1}), layout);
    Journal journal(file, std::vector<std::uint8_t>(tiles, 0), std::chrono::hours(1));
    std::vector<AppendedTile> written;
    for (const std::uint64_t t : spread) written.push_back(appended(t));
    journal.record(written);
    EXPECT_EQ(journal.tiles_done(), spread.size());

    const JournalRecord before = read_journal(file, spread);
    ASSERT_EQ(before.checksums.size(), spread.size());
    ASSERT_EQ(before.stored.size(), spread.size());
    for (std::size_t i = 0; i < spread.size(); ++i) {
        const AppendedTile a = appended(spread[i]);
        EXPECT_EQ(before.checksums[i], a.checksum) << "tile " << spread[i];
        EXPECT_EQ(before.stored[i].address, a.stored.address) << "tile " << spread[i];
        EXPECT_EQ(before.stored[i].counts_bytes, a.stored.counts_bytes);
        EXPECT_EQ(before.stored[i].outcomes_bytes, a.stored.outcomes_bytes);
    }
    EXPECT_EQ(flags_in(path, layout), std::vector<std::uint8_t>(tiles, 0)) << "a flag written before its checkpoint";

    EXPECT_FALSE(journal.checkpoint(false)) << "the interval has not passed";
    EXPECT_TRUE(journal.checkpoint(true));
    std::vector<std::uint8_t> expected(tiles, 0);
    for (const std::uint64_t t : spread) expected[t] = 1;
    EXPECT_EQ(flags_in(path, layout), expected);
    EXPECT_FALSE(journal.checkpoint(true)) << "nothing changed since the last one";
    EXPECT_EQ(std::vector<std::uint8_t>(journal.done().begin(), journal.done().end()), expected);

    // Tiles not recorded read as the file holds them: zeros.
    const JournalRecord other = read_journal(file, std::vector<std::uint64_t>{3, 299998});
    EXPECT_EQ(other.checksums, (std::vector<std::uint64_t>{0, 0}));
}

TEST(Journal, UncompressedRecordsChecksumsOnly)
{
    const TempDir dir("superball-journal");
    const fs::path path = dir / "partial.h5";
    const PartialLayout layout = journal_file(path, tiles, false);
    PartialFile file(path, Tiling({tiles}, {1}), layout);
    std::vector<std::uint8_t> resumed(tiles, 0);
    resumed[4] = 1;  // done by an earlier run
    Journal journal(file, resumed, std::chrono::hours(1));
    std::vector<TileReport> reports;
    for (const std::uint64_t t : spread) reports.push_back({t, 77 * t + 1});
    // A run longer than one write gathers (8192 tiles).
    std::vector<std::uint64_t> run(20001);
    for (std::uint64_t i = 0; i < run.size(); ++i) run[i] = 100000 + i;
    for (const std::uint64_t t : run) reports.push_back({t, 77 * t + 1});
    journal.record(reports);
    EXPECT_EQ(journal.tiles_done(), spread.size() + run.size() + 1);
    const JournalRecord r = read_journal(file, spread);
    EXPECT_TRUE(r.stored.empty());
    for (std::size_t i = 0; i < spread.size(); ++i) EXPECT_EQ(r.checksums[i], 77 * spread[i] + 1);
    const JournalRecord in_run = read_journal(file, run);
    for (std::size_t i = 0; i < run.size(); ++i) ASSERT_EQ(in_run.checksums[i], 77 * run[i] + 1) << "tile " << run[i];
    ASSERT_TRUE(journal.checkpoint(true));
    const std::vector<std::uint8_t> flags = flags_in(path, layout);
    EXPECT_EQ(flags[4], 1) << "the range written holds the earlier run's flag as it is in memory";
    EXPECT_EQ(flags[3], 0);
    for (const std::uint64_t t : spread) EXPECT_EQ(flags[t], 1) << "tile " << t;
}

}  // namespace
}  // namespace superball
