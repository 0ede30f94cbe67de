// run_explore (run/explore.hpp) under MPI, at whatever rank count the test runs with
// (ctest: 1 to 4): the result equals the kernel applied point by point, with no MPI, so
// every rank count gives the same file; a run stopped part-way keeps only its partial
// file and --resume completes it to the same result; refinement does not depend on the
// rank count; rank 0's observer sees every tile once; plans refuse alike on every rank.
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
#include "run/refine.hpp"
#include "run/tile_counter.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

const mpi::Comm world = mpi::Comm::world();

// A directory of rank 0's making, the same path on every rank, removed at the end.
class SharedDir {
public:
    SharedDir()
    {
        std::string p;
        if (world.is_root()) {
            std::string templ = (fs::temp_directory_path() / "superball-runs-XXXXXX").string();
            p = mkdtemp(templ.data()) ? templ : "";
        }
        world.broadcast(p);
        if (p.empty()) throw std::runtime_error("mkdtemp failed");
        path_ = p;
    }
    ~SharedDir()
    {
        world.barrier();
        std::error_code ec;
        if (world.is_root()) fs::remove_all(path_, ec);
    }
    SharedDir(const SharedDir&) = delete;
    SharedDir& operator=(const SharedDir&) = delete;
    fs::path operator/(const std::string& name) const { return path_ / name; }

private:
    fs::path path_;
};

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

TEST(RunExplore, EqualsTheKernelPointByPointAtAnyRankCount)
{
    const SharedDir dir;
    const Job job = job_of();
    Tally tally;
    const RunSummary r = run_explore(job, settings(dir / "r.h5"), world, tally, never);
    EXPECT_TRUE(r.complete);
    EXPECT_FALSE(r.interrupted);
    EXPECT_EQ(r.points_this_run, job.points());
    EXPECT_EQ(r.ranks, world.size());
    std::uint64_t histogram = 0;
    for (const std::uint64_t n : r.outcomes) histogram += n;
    EXPECT_EQ(histogram, job.points());
    if (world.is_root()) {
        EXPECT_EQ(tally.starts, 1);
        EXPECT_EQ(tally.computes, 1);
        EXPECT_EQ(tally.finishes, 1);
        EXPECT_EQ(tally.tiles, tally.start.tiles);  // every tile once
        EXPECT_EQ(tally.points, job.points());
        const Data got = read_result(dir / "r.h5");
        const Data want = direct(job);
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
        EXPECT_FALSE(fs::exists(layout::partial_path(dir / "r.h5")));
        EXPECT_TRUE(fs::exists(dir / "r.xmf"));
    }
}

TEST(RunExplore, StoppedRunKeepsOnlyItsPartialFileAndResumesToTheSameResult)
{
    const SharedDir dir;
    // Tiles of 16 points: about 180 of them; the journal at every report.
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const fs::path out = dir / "stopped.h5";
    // Rank 0 asks for a stop the tenth of the tiles' count time it is asked (it is asked
    // between its tiles, and its first block is larger than that at up to 4 ranks: it has
    // computed tiles by then). Not from the tiles reported: a lone rank reports every
    // second, long after this job is done.
    Tally tally;
    std::uint64_t polls = 0;
    const StopRequested stop = [&] {
        return world.is_root() && tally.start.tiles > 0 && ++polls > tally.start.tiles / 10;
    };
    ExploreSettings first_settings = settings(out);
    first_settings.command = "first run";
    const RunSummary first = run_explore(job, first_settings, world, tally, stop);
    EXPECT_TRUE(first.interrupted);
    EXPECT_FALSE(first.complete);
    if (world.is_root()) {
        EXPECT_FALSE(fs::exists(out));
        ASSERT_TRUE(fs::exists(layout::partial_path(out)));
        const ResultReader partial(layout::partial_path(out));
        EXPECT_EQ(partial.info().kind, FileKind::partial);
        // Provenance: the run that made the file, recorded once although it wrote its
        // figures at the start and at the stop.
        EXPECT_EQ(partial.info().history.rfind(partial.info().date_created + " first run [", 0), 0u) << partial.info().history;
        EXPECT_EQ(partial.info().history.find('\n'), std::string::npos) << partial.info().history;
        EXPECT_EQ(partial.info().source, software_source());
        EXPECT_EQ(partial.info().mpi_ranks, world.size());
        EXPECT_GE(partial.info().mpi_hosts, 1);
        EXPECT_EQ(partial.info().threads, 1);
        EXPECT_GT(partial.info().tiles_done, 0u);
        EXPECT_LT(partial.info().tiles_done, partial.info().tiles);
        EXPECT_TRUE(partial.damaged_tiles().empty());
    }
    // Without --resume the interrupted run is refused, on every rank alike.
    Tally refused;
    EXPECT_THROW(run_explore(job, settings(out), world, refused, never), InputError);
    Tally again;
    ExploreSettings resumed = settings(out, true, false, scalar_kernel().count);
    resumed.command = "second run";
    const RunSummary second = run_explore(job, resumed, world, again, never);
    EXPECT_TRUE(second.complete);
    EXPECT_LT(second.points_this_run, job.points());  // only the tiles not done
    if (world.is_root()) {
        // The resume's line follows the first run's; date_created stays the first run's.
        const ResultInfo info = ResultReader(out).info();
        const std::size_t newline = info.history.find('\n');
        ASSERT_NE(newline, std::string::npos) << info.history;
        EXPECT_EQ(info.history.rfind(info.date_created + " first run [", 0), 0u) << info.history;
        EXPECT_NE(info.history.find(" second run [", newline), std::string::npos) << info.history;
        EXPECT_NE(info.history.find("kernel scalar]", newline), std::string::npos) << info.history;
        EXPECT_EQ(info.history.find('\n', newline + 1), std::string::npos) << info.history;
        EXPECT_GT(again.start.tiles_done, 0u);
        EXPECT_EQ(again.start.tiles_done + again.tiles, again.start.tiles);
        const Data got = read_result(out);
        const Data want = direct(job);
        EXPECT_EQ(got.counts, want.counts);
        EXPECT_EQ(got.outcomes, want.outcomes);
        EXPECT_FALSE(fs::exists(layout::partial_path(out)));
    }
    // Complete: --resume has nothing to do.
    Tally nothing;
    const RunSummary third = run_explore(job, settings(out, true, false), world, nothing, never);
    EXPECT_TRUE(third.nothing_to_do);
}

// Runs `job` with `s` (not resuming), stopped by rank 0 once tiles are recorded or when it
// has been asked 1/`part` of the tiles' count times (it is asked between its tiles), then
// resumes it: the result is `want`. The recorded tiles as well: under AddressSanitizer, 3
// ranks with 2 writers finished every tile before rank 0 had been asked 18 times.
void expect_stopped_and_resumed(const Job& job, ExploreSettings s, const Data& want, std::uint64_t part)
{
    Tally first;
    std::uint64_t polls = 0;
    const StopRequested stop = [&] {
        return world.is_root() && first.start.tiles > 0 && (first.tiles > 0 || ++polls > first.start.tiles / part);
    };
    EXPECT_TRUE(run_explore(job, s, world, first, stop).interrupted);
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
    const StopRequested stop = [&] { return world.is_root() && first.start.tiles > 0 && ++polls > first.start.tiles / 10; };
    // The same on every rank: a failure leaves the test on every rank alike.
    ASSERT_TRUE(run_explore(job, settings(out), world, first, stop).interrupted);
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
    EXPECT_THROW(plan_explore(job, settings(out), world), InputError);
    const Job other = job_of("tile_points = 64", 999);
    EXPECT_THROW(plan_explore(other, settings(out, true, false), world), InputError);
    EXPECT_EQ(plan_explore(job, settings(out, false, true), world).mode, PlanMode::fresh);
    EXPECT_EQ(plan_explore(job, settings(out, true, false), world).mode, PlanMode::complete);
    // Not superball's: refused even with --overwrite, and left as it was.
    const fs::path text = dir / "thesis.tex";
    if (world.is_root()) {
        std::FILE* f = std::fopen(text.c_str(), "w");
        ASSERT_NE(f, nullptr);
        std::fputs("\\documentclass{article}\n", f);
        std::fclose(f);
    }
    world.barrier();
    EXPECT_THROW(plan_explore(job, settings(text, false, true), world), InputError);
    if (world.is_root()) {
        EXPECT_EQ(fs::file_size(text), 24u);
    }
}

}  // namespace
}  // namespace superball
