// The files already there (run/files_there.hpp), described once: what each path holds, the
// decision `explore --dry-run` shows from that description alone (it changes nothing: no
// directory made, no undo log applied), and the run that then applies the undo log.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/hdf5.hpp"
#include "io/layout.hpp"
#include "io/placed_chunks.hpp"
#include "run/explore_threads.hpp"
#include "run/files_there.hpp"
#include "../../temp_dir.hpp"
#include "../explore_fixture.hpp"

namespace superball::test_support {
namespace {

namespace fs = std::filesystem;

ExploreSettings output_settings(const fs::path& out, bool resume = false)
{
    ExploreSettings s;
    s.output = out;
    s.resume = resume;
    return s;
}

TEST(FilesThere, NothingThereIsANewRunAndTheDryRunMakesNoDirectory)
{
    const TempDir dir{"superball-files"};
    const fs::path out = dir / "sub" / "r.h5";
    const FilesThere f = look_at_files(out);
    EXPECT_FALSE(f.output.exists);
    EXPECT_FALSE(f.partial.exists);
    EXPECT_FALSE(f.undo_log.exists);
    EXPECT_FALSE(f.sidecar.exists);
    EXPECT_EQ(f.partial.path, layout::partial_path(out));
    const DryRun d = dry_run_explore(job_of(), output_settings(out), 2);
    ASSERT_TRUE(d.plan);
    EXPECT_EQ(d.plan->mode, PlanMode::fresh);
    EXPECT_FALSE(fs::exists(dir / "sub"));
    // Under a file, not a directory: refused as the run would refuse it.
    { std::ofstream(dir / "notes.txt") << "x\n"; }
    const DryRun under_file = dry_run_explore(job_of(), output_settings(dir / "notes.txt" / "r.h5"), 2);
    EXPECT_FALSE(under_file.plan);
    EXPECT_NE(under_file.refusal.find("cannot write the result"), std::string::npos) << under_file.refusal;
}

TEST(FilesThere, ACompleteResultAndItsSidecarAreSuperballs)
{
    const TempDir dir{"superball-files"};
    const Job job = job_of();
    const fs::path out = dir / "r.h5";
    Tally t;
    ASSERT_TRUE(run_explore_threads(job, output_settings(out), 2, t, never).complete);
    const FilesThere f = look_at_files(out);
    ASSERT_TRUE(f.output.info);
    EXPECT_EQ(f.output.info->kind, FileKind::result);
    EXPECT_FALSE(f.partial.exists);
    EXPECT_TRUE(f.sidecar.exists);
    EXPECT_TRUE(f.sidecar.ours);
    const DryRun again = dry_run_explore(job, output_settings(out), 2);
    EXPECT_FALSE(again.plan);
    EXPECT_NE(again.refusal.find("already holds a complete result"), std::string::npos) << again.refusal;
    const DryRun resumed = dry_run_explore(job, output_settings(out, true), 2);
    ASSERT_TRUE(resumed.plan);
    EXPECT_EQ(resumed.plan->mode, PlanMode::complete);
    // Another program's file where the sidecar goes: refused, named, left alone.
    { std::ofstream(layout::sidecar_path(out)) << "my notes\n"; }
    const DryRun foreign = dry_run_explore(job, output_settings(out, true), 2);
    EXPECT_FALSE(foreign.files.sidecar.ours);
    EXPECT_NE(foreign.refusal.find("ParaView sidecar"), std::string::npos) << foreign.refusal;
    EXPECT_NE(foreign.refusal.find(foreign.files.sidecar.identity.description), std::string::npos) << foreign.refusal;
    EXPECT_EQ(fs::file_size(layout::sidecar_path(out)), 9u);
}

// A finish interrupted half-way (as io/placed_chunks.hpp's undo log records it): the dry run
// says the run would undo it first and leaves every byte; the resume undoes it and completes.
TEST(FilesThere, APendingUndoLogIsShownNotApplied)
{
    const TempDir dir{"superball-files"};
    const Job job = job_of("tile_points = 16\ncheckpoint_seconds = 0.01");
    const fs::path out = dir / "undo.h5";
    const fs::path partial = layout::partial_path(out);
    std::atomic<int> polls{0};
    Tally first;
    ASSERT_TRUE(run_explore_threads(job, output_settings(out), 1, first, [&] { return ++polls > 20; }).interrupted);
    {
        PlacedChunks file(partial);
        h5::write_attribute(file.file(), layout::kind_attribute, layout::kind_result);
        h5::unlink(file.file(), "/progress");
        file.close();
    }
    const fs::path undo = PlacedChunks::undo_path(partial);
    const auto partial_bytes = fs::file_size(partial), undo_bytes = fs::file_size(undo);
    const DryRun d = dry_run_explore(job, output_settings(out, true), 2);
    EXPECT_TRUE(d.files.undo_log.ours);
    EXPECT_TRUE(d.files.partial.exists);
    const std::string said = d.plan ? d.plan->note : d.refusal;
    EXPECT_NE(said.find("undoes its changes first"), std::string::npos) << said;
    EXPECT_EQ(fs::file_size(partial), partial_bytes);
    EXPECT_EQ(fs::file_size(undo), undo_bytes);
    Tally second;
    ASSERT_TRUE(run_explore_threads(job, output_settings(out, true), 2, second, never).complete);
    EXPECT_GT(second.start.tiles_done, 0u);
    EXPECT_NE(second.start.note.find("its changes were undone"), std::string::npos) << second.start.note;
    EXPECT_FALSE(fs::exists(undo));
    const Data got = read_result(out);
    const Data want = direct(job);
    EXPECT_EQ(got.counts, want.counts);
    EXPECT_EQ(got.outcomes, want.outcomes);
}

}  // namespace
}  // namespace superball::test_support
