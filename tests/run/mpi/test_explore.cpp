// run_explore (run/explore.hpp) under MPI, at whatever rank count the test runs with
// (ctest: 1 to 4), where it differs from a run on threads (the lifecycle both share:
// tests/run/lifecycle_suite.hpp): the schedule's figures, many writers, the interleaved
// hand-out, compressed and uncompressed data after a stop, a finish interrupted half-way,
// refinement independent of the rank count, plans refused alike on every rank.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"
#include "io/hdf5.hpp"
#include "io/layout.hpp"
#include "io/placed_chunks.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "mpi/mpi.hpp"
#include "run/explore.hpp"
#include "../explore_fixture.hpp"
#include "shared_dir.hpp"
#include "run/refine.hpp"
#include "run/tile_counter.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

using test_support::world;

using namespace test_support;  // job_of, direct, read_result, Data, Tally, never (explore_fixture.hpp)

// Settings for an output: the best kernel of this processor unless told otherwise (the
// scalar one gives the same bits, tests/core/test_kernels.cpp).
ExploreSettings settings(const fs::path& out, bool resume = false, bool overwrite = false,
                         CountKernel kernel = best_kernel().count)
{
    ExploreSettings s;
    s.output = out;
    s.resume = resume;
    s.overwrite = overwrite;
    s.kernel = kernel;
    return s;
}

// A stop rank 0 asks for once tiles are recorded or when it has been asked 1/`part` of the
// tiles' count times (it is asked between its tiles). The recorded tiles as well: under
// AddressSanitizer, 3 ranks with 2 writers finished every tile before rank 0 had been asked
// 18 times (and, beside other tests, before it had been asked a tenth of the tiles' count).
StopRequested stop_early(const Tally& first, std::uint64_t& polls, std::uint64_t part)
{
    return [&first, &polls, part] {
        return world.is_root() && first.start.tiles > 0 && (first.tiles > 0 || ++polls > first.start.tiles / part);
    };
}

// Runs `job` with `s` (not resuming), stopped early (stop_early), then resumes it: the
// result is `want`.
void expect_stopped_and_resumed(const Job& job, ExploreSettings s, const Data& want, std::uint64_t part)
{
    Tally first;
    std::uint64_t polls = 0;
    EXPECT_TRUE(run_explore(job, s, world, first, stop_early(first, polls, part)).interrupted);
    s.resume = true;
    Tally second;
    EXPECT_TRUE(run_explore(job, s, world, second, never).complete);
    if (world.is_root()) {
        EXPECT_GT(second.start.tiles_done, 0u);
        EXPECT_EQ(second.start.tiles_done + second.tiles, second.start.tiles);
        const Data got = read_result(s.output);
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
    }
}

// The schedule's figures (explore --stats, what tests/scale/validate.sh --oversubscribed
// compares with the simulation): every tile counted once, by every rank below 64, and
// node leaders exactly when the ranks form several nodes (here pseudo-nodes, --node-ranks).
TEST(RunExplore, ScheduleFiguresCountEveryTileOnce)
{
    const SharedDir dir;
    const Job job = job_of();
    for (const int node_ranks : {0, 2}) {
        ExploreSettings s = settings(dir / ("nodes" + std::to_string(node_ranks) + ".h5"));
        s.node_ranks = node_ranks;
        Tally tally;
        const RunSummary r = run_explore(job, s, world, tally, never);
        ASSERT_TRUE(r.complete);
        const ScheduleFigures& f = r.schedule;
        if (world.is_root()) {
            EXPECT_EQ(f.tiles, tally.start.tiles);
        }
        EXPECT_EQ(f.computing_ranks, world.size());
        EXPECT_LE(f.tiles_min, f.tiles_max);
        EXPECT_GE(f.tiles_max * static_cast<std::uint64_t>(world.size()), f.tiles);
        EXPECT_GE(f.root_blocks, 1u);
        // Pseudo-nodes of 2: several from 3 ranks on (one rank a node gains nothing from a leader).
        EXPECT_EQ(f.two_level, node_ranks == 2 && world.size() > 2) << "node_ranks " << node_ranks;
        if (world.size() == 1) {
            EXPECT_EQ(f.root_messages, 0u);
        }
    }
}

// Node leaders writing compressed tiles beside rank 0 (ExploreSettings::writers, pseudo-nodes
// of 2 ranks: two nodes at 3 and 4 ranks, one writer below): the same data whatever the
// writers, every tile written once by one of them, fresh and after a stop and a resume, in
// stripes of the job's alignment; a writer count above the nodes' is capped and said.
TEST(RunExplore, ManyWritersWriteTheSameResult)
{
    const SharedDir dir;
    const Job job = job_of("tile_points = 16\nalignment = 4096\ncheckpoint_seconds = 0.01");
    const Data want = direct(job);
    const int nodes = world.size() > 2 ? (world.size() + 1) / 2 : 1;
    for (const std::uint32_t writers : {0u, 2u, 5u}) {
        ExploreSettings s = settings(dir / ("w" + std::to_string(writers) + ".h5"));
        s.node_ranks = 2;
        s.writers = writers;
        Tally tally;
        const RunSummary r = run_explore(job, s, world, tally, never);
        ASSERT_TRUE(r.complete);
        const int expected = writers == 0 ? 1 : std::min<int>(static_cast<int>(writers), nodes);  // auto: 1 below 64 ranks
        EXPECT_EQ(r.schedule.writers, expected) << "writers " << writers;
        // A leader writes its node's tiles: when every rank counted some (on a loaded machine
        // the first node's ranks can count every tile before the second's start).
        if (expected > 1 && r.schedule.tiles_min > 0) {
            EXPECT_GT(r.schedule.placed_max, 0u) << "a leader wrote tiles";
        }
        if (world.is_root()) {
            const Data got = read_result(s.output);
            EXPECT_EQ(got.counts, want.counts) << "writers " << writers;
            EXPECT_EQ(got.outcomes, want.outcomes) << "writers " << writers;
            const bool capped = static_cast<int>(writers) > nodes;
            EXPECT_EQ(tally.start.note.find("writers asked") != std::string::npos, capped) << tally.start.note;
        }
        s.output = dir / ("w" + std::to_string(writers) + "-resumed.h5");
        expect_stopped_and_resumed(job, s, want, 10);
    }
}

// Tiles handed out interleaved (as from 64 ranks on, job/tiles.hpp handout_order), here at
// any rank count: the same result, and a stopped run resumes to it (its incomplete
// granules go last).
TEST(RunExplore, InterleavedHandoutGivesTheSameResultAndResumes)
{
    const SharedDir dir;
    // 4096 tiles of 16 points in granules of 128 (4096 bytes of counts, the alignment).
    const Job job = parse_job("[model]\ne = 0.9\nalpha = 0.9\n[grid]\nxi = { min = 0.0, max = 1.0, n = 256 }\nU = -1.0\n"
                              "W = { min = -3.0, max = 3.0, n = 256 }\n[run]\nmax_bounces = 1000\ntile_points = 16\n"
                              "alignment = 4096\ncheckpoint_seconds = 0.01\n",
                              "interleaved job");
    ExploreSettings s = settings(dir / "whole.h5");
    s.interleave_ranks = 1;
    Tally tally;
    EXPECT_TRUE(run_explore(job, s, world, tally, never).complete);
    const Data want = direct(job);
    if (world.is_root()) {
        const Data got = read_result(dir / "whole.h5");
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
    }
    s.output = dir / "stopped.h5";
    expect_stopped_and_resumed(job, s, want, 10);
}

// Tiles compressed by the ranks and appended by rank 0, or written uncompressed by each
// rank to its chunk ([run] compression = 0), 16- and 32-bit counts, full and edge tiles:
// the same data, fresh and after a stop and resume; the result's chunks are the tiles.
TEST(RunExplore, CompressedAndUncompressedResultsHoldTheSameData)
{
    const SharedDir dir;
    for (const int max_bounces : {1000, 70000}) {
        for (const std::string compression : {"0", "1", "6"}) {
            // 61 x 47 points in tiles of 16 x 12 (edge tiles on both axes).
            const Job job = job_of("tile_points = 256\ncheckpoint_seconds = 0.01\ncompression = " + compression, max_bounces);
            const Data want = direct(job);
            const std::string name = "c" + compression + "-" + std::to_string(max_bounces);
            Tally tally;
            EXPECT_TRUE(run_explore(job, settings(dir / (name + ".h5")), world, tally, never).complete);
            if (world.is_root()) {
                const Data got = read_result(dir / (name + ".h5"));
                EXPECT_EQ(got.counts, want.counts) << name;
                EXPECT_EQ(got.outcomes, want.outcomes) << name;
                const h5::Id file = h5::open_file(dir / (name + ".h5"), false);
                const h5::Storage st = h5::dataset_storage(h5::open_dataset(file, layout::wall_bounces));
                const Extent tile = default_tiling(job, world.size()).tile_shape();
                EXPECT_EQ(st.chunk, std::vector<hsize_t>(tile.begin(), tile.end())) << name;
                EXPECT_EQ(st.deflate_level, compression == "0" ? -1 : std::stoi(compression)) << name;
                EXPECT_TRUE(st.allocated) << name;
            }
            expect_stopped_and_resumed(job, settings(dir / (name + "-resumed.h5")), want, 5);
        }
    }
}

// A run killed while rank 0 was making its partial file the result (io/placed_chunks.hpp)
// leaves an undo log; the next run puts the partial file back as it was and finishes it.
TEST(RunExplore, AFinishInterruptedHalfWayIsUndoneAndResumed)
{
    const SharedDir dir;
    // Tiles of 16 points, as in the test of a stopped run: rank 0 is asked for a stop often
    // enough at any rank count.
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const Data want = direct(job);
    const fs::path out = dir / "undo.h5";
    Tally first;
    std::uint64_t polls = 0;
    // The same on every rank: a failure leaves the test on every rank alike.
    ASSERT_TRUE(run_explore(job, settings(out), world, first, stop_early(first, polls, 10)).interrupted);
    const fs::path partial = layout::partial_path(out);
    if (world.is_root()) {
        // What an interrupted finish leaves: some of the file's bytes overwritten, more
        // appended, the log of what was there.
        const auto before = fs::file_size(partial);
        {
            PlacedChunks file(partial);
            h5::write_attribute(file.file(), layout::kind_attribute, layout::kind_result);
            h5::check(H5Ldelete(file.file(), "/progress", H5P_DEFAULT), "H5Ldelete");
            file.close();
        }
        EXPECT_TRUE(fs::exists(PlacedChunks::undo_path(partial)));
        EXPECT_THROW(ResultReader{partial}, FormatError);  // a result with no chunks: not readable
        (void)before;
    }
    ExploreSettings s = settings(out, true);
    Tally second;
    EXPECT_TRUE(run_explore(job, s, world, second, never).complete);
    if (world.is_root()) {
        EXPECT_GT(second.start.tiles_done, 0u);
        const Data got = read_result(out);
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
        EXPECT_FALSE(fs::exists(PlacedChunks::undo_path(partial)));
    }
}

TEST(RunExplore, RefinementDoesNotDependOnTheRankCount)
{
    const SharedDir dir;
    const Job job = job_of("refine = 8");
    Tally tally;
    const RunSummary r = run_explore(job, settings(dir / "refined.h5"), world, tally, never);
    EXPECT_TRUE(r.complete);
    EXPECT_LT(r.points_counted, job.points());  // refinement computed fewer points
    if (world.is_root()) {
        // The same tiles refined one after the other, with no MPI and no files.
        const Grid grid(job);
        const Tiling tiling = default_tiling(job, 1);
        TileCounter counter(&count_each, job.max_bounces);
        Data want{std::vector<std::uint32_t>(job.points()), std::vector<std::uint8_t>(job.points())};
        Starts starts;
        std::vector<ModelRun> runs;
        const Extent shape = grid.shape();
        for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
            const Box box = tiling.box(t);
            grid.starts(box, starts);
            grid.model_runs(box, runs);
            std::vector<std::uint32_t> c(starts.size());
            std::vector<std::uint8_t> o(starts.size());
            const CountPoints some = [&](std::span<const std::uint64_t> points) {
                counter.some(points, starts, runs, c, o, Serve());
            };
            refine_tile(box.count, job.refine, some, c, o);
            for (std::uint64_t i = 0; i < box.count[0]; ++i) {
                for (std::uint64_t j = 0; j < box.count[1]; ++j) {
                    const std::uint64_t at = (box.start[0] + i) * shape[1] + box.start[1] + j;
                    want.counts[at] = c[i * box.count[1] + j];
                    want.outcomes[at] = o[i * box.count[1] + j];
                }
            }
        }
        const Data got = read_result(dir / "refined.h5");
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
    }
}

TEST(RunExplore, PlansRefuseAlikeOnEveryRank)
{
    const SharedDir dir;
    const Job job = job_of();
    const fs::path out = dir / "done.h5";
    Tally tally;
    run_explore(job, settings(out), world, tally, never);
    // An existing result without --overwrite or --resume; another job's result with --resume.
    EXPECT_THROW(plan_explore(job, settings(out), Team::ranks(world)), InputError);
    const Job other = job_of("tile_points = 64", 999);
    EXPECT_THROW(plan_explore(other, settings(out, true, false), Team::ranks(world)), InputError);
    EXPECT_EQ(plan_explore(job, settings(out, false, true), Team::ranks(world)).mode, PlanMode::fresh);
    EXPECT_EQ(plan_explore(job, settings(out, true, false), Team::ranks(world)).mode, PlanMode::complete);
    // Not superball's: refused even with --overwrite, and left as it was.
    const fs::path text = dir / "thesis.tex";
    if (world.is_root()) {
        std::FILE* f = std::fopen(text.c_str(), "w");
        ASSERT_NE(f, nullptr);
        std::fputs("\\documentclass{article}\n", f);
        std::fclose(f);
    }
    world.barrier();
    EXPECT_THROW(plan_explore(job, settings(text, false, true), Team::ranks(world)), InputError);
    if (world.is_root()) {
        EXPECT_EQ(fs::file_size(text), 24u);
    }
}

}  // namespace
}  // namespace superball
