// One suite for a run's lifecycle (run/lifecycle.hpp) over either team: the result equals the
// kernel point by point, compressed or not; a stopped run keeps only its partial file and
// resumes to the same result; a damaged done tile, an existing output and a file that is not
// superball's are refused in the same words. Written once, run over every team in process:
// MPI ranks and threads in tests/run/mpi/test_lifecycle.cpp (test_runs, 1 to 4 ranks), threads
// alone, with no MPI at all, in tests/run/threads/test_lifecycle.cpp.
//
// A Runner is a team and a scratch directory: `dir / name` (the same path on every process),
// `run(job, settings, observer, stop, threads)` (collective; `threads` counts in a team of
// threads, a team of ranks ignores it), `root()` (the process whose observer is told and
// that looks at the files), `sync()` (every process waits for the others), `ranks()` and
// `threads(asked)`, the provenance a run records.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/result_reader.hpp"
#include "run/explore.hpp"
#include "run/explore_threads.hpp"
#include "../temp_dir.hpp"
#include "explore_fixture.hpp"

namespace superball::test_support {

inline ExploreSettings settings_for(const std::filesystem::path& out, bool resume = false, bool overwrite = false)
{
    ExploreSettings s;
    s.output = out;
    s.resume = resume;
    s.overwrite = overwrite;
    s.command = "test run";
    return s;
}

// The team of threads of this process (run_explore_threads), in a directory of its own.
struct OnThreads {
    TempDir dir{"superball-lifecycle"};
    std::filesystem::path operator/(const std::string& name) const { return dir / name; }
    RunSummary run(const Job& job, const ExploreSettings& s, RunObserver& observer, const StopRequested& stop,
                   unsigned threads)
    {
        return run_explore_threads(job, s, threads, observer, stop);
    }
    bool root() const { return true; }
    void sync() const {}
    int ranks() const { return 1; }
    int threads(unsigned asked) const { return static_cast<int>(asked); }
};

template <class Runner>
class Lifecycle : public testing::Test {
protected:
    Runner team;
};

TYPED_TEST_SUITE_P(Lifecycle);

TYPED_TEST_P(Lifecycle, EqualsTheKernelPointByPoint)
{
    auto& team = this->team;
    for (const char* run : {"tile_points = 64", "tile_points = 64\ncompression = 0\nalignment = 4096"}) {
        const Job job = job_of(run);
        for (const unsigned threads : {1u, 3u}) {
            SCOPED_TRACE(testing::Message() << run << ", " << threads << " threads asked");
            const std::string name = "r" + std::to_string(threads) + std::to_string(job.compression);
            const std::filesystem::path out = team / (name + ".h5");
            Tally tally;
            const RunSummary r = team.run(job, settings_for(out), tally, never, threads);
            EXPECT_TRUE(r.complete);
            EXPECT_FALSE(r.interrupted);
            EXPECT_EQ(r.points_this_run, job.points());
            EXPECT_EQ(r.ranks, team.ranks());
            std::uint64_t histogram = 0;
            for (const std::uint64_t n : r.outcomes) histogram += n;
            EXPECT_EQ(histogram, job.points());
            if (!team.root()) continue;
            EXPECT_EQ(tally.starts, 1);
            EXPECT_EQ(tally.computes, 1);
            EXPECT_EQ(tally.finishes, 1);
            EXPECT_EQ(tally.tiles, tally.start.tiles);  // every tile once
            EXPECT_EQ(tally.points, job.points());
            const Data got = read_result(out);
            const Data want = direct(job);
            EXPECT_EQ(got.counts, want.counts);
            EXPECT_EQ(got.outcomes, want.outcomes);
            EXPECT_FALSE(std::filesystem::exists(layout::partial_path(out)));
            EXPECT_TRUE(std::filesystem::exists(team / (name + ".xmf")));
            const ResultInfo info = ResultReader(out).info();
            EXPECT_EQ(info.mpi_ranks, team.ranks());
            EXPECT_EQ(info.threads, team.threads(threads));
            EXPECT_EQ(info.history.rfind(info.date_created + " test run [", 0), 0u) << info.history;
        }
    }
}

// Stopped by the root the tenth time it is asked (between its tiles), then resumed: only
// the tiles left are counted, and the result is the kernel's. One thread in a team of
// threads: with two, a loaded machine let the other thread count every tile before the
// calling one had been asked that often (the run completed, not stopped).
TYPED_TEST_P(Lifecycle, StoppedRunKeepsOnlyItsPartialFileAndResumesToTheSameResult)
{
    auto& team = this->team;
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const std::filesystem::path out = team / "stopped.h5";
    Tally first;
    std::uint64_t polls = 0;
    const StopRequested stop = [&] { return team.root() && first.start.tiles > 0 && ++polls > first.start.tiles / 10; };
    ExploreSettings first_settings = settings_for(out);
    first_settings.command = "first run";
    const RunSummary r = team.run(job, first_settings, first, stop, 1);
    EXPECT_TRUE(r.interrupted);
    EXPECT_FALSE(r.complete);
    if (team.root()) {
        EXPECT_FALSE(std::filesystem::exists(out));
        const ResultReader partial(layout::partial_path(out));
        EXPECT_EQ(partial.info().kind, FileKind::partial);
        EXPECT_GT(partial.info().tiles_done, 0u);
        EXPECT_LT(partial.info().tiles_done, partial.info().tiles);
        EXPECT_TRUE(partial.damaged_tiles().empty());
        // Provenance: the run that made the file, recorded once although it wrote its
        // figures at the start and at the stop.
        EXPECT_EQ(partial.info().history.rfind(partial.info().date_created + " first run [", 0), 0u) << partial.info().history;
        EXPECT_EQ(partial.info().history.find('\n'), std::string::npos) << partial.info().history;
    }
    // Refused without --resume, on every process alike; resumed, only the tiles left.
    Tally refused;
    EXPECT_THROW(team.run(job, settings_for(out), refused, never, 2), InputError);
    Tally second;
    ExploreSettings resumed_settings = settings_for(out, true);
    resumed_settings.command = "second run";
    const RunSummary resumed = team.run(job, resumed_settings, second, never, 3);
    EXPECT_TRUE(resumed.complete);
    EXPECT_LT(resumed.points_this_run, job.points());
    if (team.root()) {
        EXPECT_GT(second.start.tiles_done, 0u);
        EXPECT_EQ(second.start.tiles_done + second.tiles, second.start.tiles);
        const Data got = read_result(out);
        const Data want = direct(job);
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
        EXPECT_FALSE(std::filesystem::exists(layout::partial_path(out)));
        // The resume's line follows the first run's; date_created stays the first run's.
        const ResultInfo info = ResultReader(out).info();
        const std::size_t newline = info.history.find('\n');
        ASSERT_NE(newline, std::string::npos) << info.history;
        EXPECT_EQ(info.history.rfind(info.date_created + " first run [", 0), 0u) << info.history;
        EXPECT_NE(info.history.find(" second run [", newline), std::string::npos) << info.history;
        EXPECT_EQ(info.history.find('\n', newline + 1), std::string::npos) << info.history;
    }
    Tally nothing;
    EXPECT_TRUE(team.run(job, settings_for(out, true), nothing, never, 2).nothing_to_do);
}

// A done tile whose stored bytes changed since it was recorded: the resume is refused on
// every process, naming the tile, and the file is left as it was.
TYPED_TEST_P(Lifecycle, RefusesToResumeOntoADamagedTile)
{
    auto& team = this->team;
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const std::filesystem::path out = team / "damaged.h5";
    const std::filesystem::path partial = layout::partial_path(out);
    Tally first;
    std::uint64_t polls = 0;
    const StopRequested stop = [&] { return team.root() && first.start.tiles > 0 && ++polls > first.start.tiles / 10; };
    ASSERT_TRUE(team.run(job, settings_for(out), first, stop, 1).interrupted);
    std::uint64_t tile = 0;
    std::uintmax_t bytes_before = 0;
    if (team.root()) {
        std::uint64_t address = 0;
        {
            const ResultReader reader(partial);
            const std::vector<std::uint8_t> done = reader.tiles_done();
            while (done.at(tile) == 0) ++tile;
            const Tiling tiling(reader.info().shape, reader.info().tile_shape);
            PartialFile file(partial, tiling, partial_layout(partial, tiling));
            address = read_journal(file, std::vector<std::uint64_t>{tile}).stored.at(0).address;
        }
        std::fstream f(partial, std::ios::in | std::ios::out | std::ios::binary);
        f.seekg(static_cast<std::streamoff>(address));
        const char byte = static_cast<char>(f.get() ^ 0x5a);
        f.seekp(static_cast<std::streamoff>(address));
        f.put(byte);
        f.close();
        bytes_before = std::filesystem::file_size(partial);
    }
    team.sync();
    Tally second;
    try {
        team.run(job, settings_for(out, true), second, never, 2);
        ADD_FAILURE() << "resumed onto a damaged tile";
    } catch (const InputError& e) {
        const std::string m = e.what();
        if (team.root()) {
            EXPECT_NE(m.find("(first: tile " + std::to_string(tile) + ")"), std::string::npos) << m;
        }
        EXPECT_NE(m.find("--overwrite to start again, or --output to write elsewhere"), std::string::npos) << m;
    }
    if (team.root()) {
        EXPECT_EQ(std::filesystem::file_size(partial), bytes_before);
    }
}

TYPED_TEST_P(Lifecycle, RefusesOutputsAsTheCommandLineDoes)
{
    auto& team = this->team;
    const Job job = job_of("tile_points = 256");
    const std::filesystem::path out = team / "r.h5";
    Tally t;
    EXPECT_TRUE(team.run(job, settings_for(out), t, never, 2).complete);
    EXPECT_THROW(team.run(job, settings_for(out), t, never, 2), InputError);                  // exists
    EXPECT_TRUE(team.run(job, settings_for(out, false, true), t, never, 2).complete);         // --overwrite
    const std::filesystem::path text = team / "thesis.tex";
    if (team.root()) std::ofstream(text) << "\\documentclass{article}\n";
    team.sync();
    try {
        team.run(job, settings_for(text, false, true), t, never, 2);
        ADD_FAILURE() << "a file not superball's was replaced";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not a superball file"), std::string::npos) << e.what();
    }
    if (team.root()) {
        EXPECT_EQ(std::filesystem::file_size(text), 24u);
    }
}

REGISTER_TYPED_TEST_SUITE_P(Lifecycle, EqualsTheKernelPointByPoint, StoppedRunKeepsOnlyItsPartialFileAndResumesToTheSameResult,
                            RefusesToResumeOntoADamagedTile, RefusesOutputsAsTheCommandLineDoes);

}  // namespace superball::test_support
