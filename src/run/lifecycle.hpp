// One run of an exploration job, from its plan to its summary, over a team (run/team.hpp):
// the one algorithm behind run_explore (MPI ranks) and run_explore_threads (the threads of one
// process). Its steps, in run/lifecycle.cpp:
//
//   plan     the root decides what to do with the files already there (plan_explore); every
//            process is told
//   start    the root makes the partial file, or reads it for a resume; every process learns
//            the tiling and the file's layout
//   left     the tiles left to count; a resume first checks the done ones against their
//            checksums, each process a share
//   count    the team counts them and the root records them: the one step that differs
//            (count_on_ranks under the schedule, count_on_threads)
//   close    the root records an interrupted run in the partial file, or makes it the result
//   summary  the tallies reduced over the processes, the root's figures told to every one
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "io/partial_file.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "job/tiles.hpp"
#include "run/explore.hpp"
#include "run/explore_work.hpp"
#include "run/team.hpp"

namespace superball {

// A run once its partial file is made or read, on every process: who runs it, what it
// counts, the file, and the root's record of it.
struct OpenRun {
    OpenRun(const Team& team, const Job& job, const ExplorePlan& plan, const Provenance& provenance, RunObserver& observer,
            std::chrono::steady_clock::time_point started);

    const Team& team;
    const Job& job;
    const ExplorePlan& plan;
    const Provenance& provenance;
    RunObserver& observer;  // the root's is told
    const std::chrono::steady_clock::time_point started;
    const std::filesystem::path partial;
    const Grid grid;
    StartedPartial start;  // its done flags go to the recorder
    const Tiling tiling;
    PartialFile file;
    int writers = 1;                   // processes that write compressed tiles (run/work_pool.hpp)
    std::optional<Recorder> recorder;  // the root's
};

// The tiles of a run counted: whether a stop cut it short, the tallies of this process's
// points (ExploreWork::tallies, summed over its workers), how long it took, when it ended.
struct Counted {
    bool interrupted = false;  // the same on every process
    std::vector<std::uint64_t> tallies;
    double compute_seconds = 0;  // the same on every process
    std::chrono::steady_clock::time_point end;
    ScheduleFigures figures;  // a team of ranks' (explore --stats)
};

// The step that differs: `pending` counted by the team, the root's run.recorder recording
// each tile. Over the ranks of run.team.comm() under the schedule (run/schedule.hpp), one
// thread a rank, with run.writers writers (run/explore.cpp); or on the threads of this
// process, each taking the next tiles (run/explore_threads.cpp).
Counted count_on_ranks(OpenRun& run, std::vector<ListedTile> pending, const ExploreSettings& settings,
                       const StopRequested& stop);
Counted count_on_threads(OpenRun& run, std::vector<ListedTile> pending, const ExploreSettings& settings,
                         const StopRequested& stop);

// The schedule a run's ranks follow (ExploreSettings::node_ranks, the writers asked: the
// settings', else the job's), without its granule.
ScheduleSettings schedule_settings(const ExploreSettings& settings, const Job& job);

// Collective over `team`: plans, runs and finishes `job` (run_explore's and
// run_explore_threads' contract).
RunSummary run_lifecycle(const Job& job, const ExploreSettings& settings, const Team& team, RunObserver& observer,
                         const StopRequested& stop);

}  // namespace superball
