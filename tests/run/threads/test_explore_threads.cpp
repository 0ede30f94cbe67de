// run_explore_threads (run/explore_threads.hpp), in one process without MPI: the result
// equals the kernel point by point at any thread count, compressed or not; a stopped run
// keeps its partial file and resumes to the same result; outputs are refused as by
// run_explore; the provenance says threads.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"
#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "run/explore_threads.hpp"
#include "../../temp_dir.hpp"
#include "../explore_fixture.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

using test_support::TempDir;

using namespace test_support;  // job_of, direct, read_result, Data, Tally, never (explore_fixture.hpp)

ExploreSettings settings(const fs::path& out, bool resume = false, bool overwrite = false)
{
    ExploreSettings s;
    s.output = out;
    s.resume = resume;
    s.overwrite = overwrite;
    s.command = "test run";
    return s;
}

TEST(RunExploreThreads, EqualsTheKernelPointByPointAtAnyThreadCount)
{
    const TempDir dir{"superball-threads"};
    for (const char* run : {"tile_points = 64", "tile_points = 64\ncompression = 0\nalignment = 4096"}) {
        const Job job = job_of(run);
        const Data want = direct(job);
        for (const unsigned threads : {1u, 2u, 5u}) {
            SCOPED_TRACE(testing::Message() << run << ", " << threads << " threads");
            const fs::path out = dir / ("r" + std::to_string(threads) + std::to_string(job.compression) + ".h5");
            Tally tally;
            const RunSummary r = run_explore_threads(job, settings(out), threads, tally, never);
            EXPECT_TRUE(r.complete);
            EXPECT_EQ(r.points_this_run, job.points());
            EXPECT_EQ(tally.tiles, tally.start.tiles);
            EXPECT_EQ(tally.points, job.points());
            std::uint64_t histogram = 0;
            for (const std::uint64_t n : r.outcomes) histogram += n;
            EXPECT_EQ(histogram, job.points());
            const Data got = read_result(out);
            EXPECT_EQ(got.counts, want.counts);
            EXPECT_EQ(got.outcomes, want.outcomes);
            EXPECT_FALSE(fs::exists(layout::partial_path(out)));
            EXPECT_TRUE(fs::exists(dir / ("r" + std::to_string(threads) + std::to_string(job.compression) + ".xmf")));
            const ResultInfo info = ResultReader(out).info();
            EXPECT_EQ(info.mpi_ranks, 1);
            EXPECT_EQ(info.threads, threads);
            EXPECT_EQ(info.history.rfind(info.date_created + " test run [", 0), 0u) << info.history;
            EXPECT_NE(info.history.find(std::to_string(threads) + " thread"), std::string::npos) << info.history;
        }
    }
}

TEST(RunExploreThreads, StoppedRunResumesToTheSameResult)
{
    const TempDir dir{"superball-threads"};
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const fs::path out = dir / "stopped.h5";
    // The calling thread asks before each of its tiles: stop after 20 of them. One thread:
    // with two, a loaded machine let the other thread count every tile before the calling
    // one had asked 20 times (the run then completed, not stopped).
    std::atomic<int> polls{0};
    const StopRequested stop = [&] { return ++polls > 20; };
    Tally first;
    const RunSummary r = run_explore_threads(job, settings(out), 1, first, stop);
    EXPECT_TRUE(r.interrupted);
    EXPECT_FALSE(fs::exists(out));
    {
        const ResultReader partial(layout::partial_path(out));
        EXPECT_GT(partial.info().tiles_done, 0u);
        EXPECT_LT(partial.info().tiles_done, partial.info().tiles);
        EXPECT_TRUE(partial.damaged_tiles().empty());
    }
    // Refused without resume; resumed, only the tiles left are counted.
    Tally refused;
    EXPECT_THROW(run_explore_threads(job, settings(out), 2, refused, never), InputError);
    Tally second;
    const RunSummary resumed = run_explore_threads(job, settings(out, true), 3, second, never);
    EXPECT_TRUE(resumed.complete);
    EXPECT_EQ(second.start.tiles_done + second.tiles, second.start.tiles);
    EXPECT_LT(resumed.points_this_run, job.points());
    const Data got = read_result(out);
    const Data want = direct(job);
    EXPECT_EQ(got.counts, want.counts);
    EXPECT_EQ(got.outcomes, want.outcomes);
    const ResultInfo info = ResultReader(out).info();
    EXPECT_NE(info.history.find('\n'), std::string::npos) << info.history;  // a line per run
    Tally nothing;
    EXPECT_TRUE(run_explore_threads(job, settings(out, true), 2, nothing, never).nothing_to_do);
}

// A done tile whose stored bytes changed since it was recorded: the resume is refused, in
// the words run_explore uses, and the file is left as it was.
TEST(RunExploreThreads, RefusesToResumeOntoADamagedTile)
{
    const TempDir dir{"superball-threads"};
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const fs::path out = dir / "damaged.h5";
    std::atomic<int> polls{0};
    Tally first;
    ASSERT_TRUE(run_explore_threads(job, settings(out), 1, first, [&] { return ++polls > 20; }).interrupted);
    const fs::path partial = layout::partial_path(out);
    std::uint64_t address = 0, tile = 0;
    {
        const ResultReader reader(partial);
        const std::vector<std::uint8_t> done = reader.tiles_done();
        while (done.at(tile) == 0) ++tile;
        const Tiling tiling(reader.info().shape, reader.info().tile_shape);
        PartialFile file(partial, tiling, partial_layout(partial, tiling));
        address = read_journal(file, std::vector<std::uint64_t>{tile}).stored.at(0).address;
    }
    {
        std::fstream f(partial, std::ios::in | std::ios::out | std::ios::binary);
        f.seekg(static_cast<std::streamoff>(address));
        const char byte = static_cast<char>(f.get() ^ 0x5a);
        f.seekp(static_cast<std::streamoff>(address));
        f.put(byte);
    }
    const auto bytes_before = fs::file_size(partial);
    Tally second;
    try {
        run_explore_threads(job, settings(out, true), 2, second, never);
        FAIL() << "resumed onto a damaged tile";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("(first: tile " + std::to_string(tile) + ")"), std::string::npos) << m;
        EXPECT_NE(m.find("--overwrite to start again, or --output to write elsewhere"), std::string::npos) << m;
    }
    EXPECT_EQ(fs::file_size(partial), bytes_before);
}

TEST(RunExploreThreads, RefusesOutputsAsTheCommandLineDoes)
{
    const TempDir dir{"superball-threads"};
    const Job job = job_of("tile_points = 256");
    const fs::path out = dir / "r.h5";
    Tally t;
    run_explore_threads(job, settings(out), 2, t, never);
    EXPECT_THROW(run_explore_threads(job, settings(out), 2, t, never), InputError);  // exists
    EXPECT_TRUE(run_explore_threads(job, settings(out, false, true), 2, t, never).complete);  // --overwrite
    const fs::path text = dir / "thesis.tex";
    { std::ofstream(text) << "\\documentclass{article}\n"; }
    try {
        run_explore_threads(job, settings(text, false, true), 2, t, never);
        ADD_FAILURE() << "a file not superball's was replaced";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not a superball file"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace superball
