// Running an exploration job on a communicator: the library function behind
// `superball explore`, for the command line, C++ tests and other front ends.
//
//   plan:   rank 0 decides what to do with the output (a new run, a resume, nothing to
//           do, or a refusal naming why), the others are told; the grid is cut into tiles.
//   run:    tiles are scheduled over the ranks, counted, written and recorded done.
//   finish: rank 0 makes the partial file the result in place (io/final_result.hpp), or
//           records the interrupted run in it, resumable.
//
// Progress goes to rank 0's RunObserver (run/progress.hpp); a stop is asked for through a
// predicate polled on every rank (StopSignals::requested for the command line). The run's
// steps are run/lifecycle.hpp's, the same as run_explore_threads'.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/kernels.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "job/tiles.hpp"
#include "mpi/mpi.hpp"
#include "run/progress.hpp"
#include "run/files_there.hpp"
#include "run/schedule.hpp"
#include "run/team.hpp"

namespace superball {

// A failure that every rank of a run raises alike (the ranks are in step): reported once.
using RunError = mpi::CollectiveError;

struct ExploreSettings {
    std::filesystem::path output;  // the result file; empty: the job's [run] output
    bool resume = false;           // finish an interrupted run of the same job
    bool overwrite = false;        // replace an existing result
    CountKernel kernel = best_kernel().count;  // core/kernels.hpp: select_kernel()
    // From this many ranks on, tiles are handed out interleaved (job/tiles.hpp,
    // handout_order); tests set 1 to interleave at any rank count.
    int interleave_ranks = interleave_ranks_default;
    // For the result's history (job/provenance.hpp): the command or call that ran the job;
    // empty: this process's command line.
    std::string command{};
    // The schedule's nodes (ScheduleSettings::node_ranks): 0, the ranks that share memory;
    // n > 0, groups of n consecutive ranks (the two-level schedule on one machine, as
    // tests/scale/validate.sh --oversubscribed runs it beside its simulation).
    int node_ranks = 0;
    // Who writes compressed tiles (Job::writers: 0 auto, else a count): this, else the job's.
    std::optional<std::uint32_t> writers{};
};

// The output path a job and settings write to: settings.output, else the job's [run]
// output; InputError if neither is given.
std::filesystem::path output_path(const Job& job, const ExploreSettings& settings);

enum class PlanMode : std::int64_t { fresh, resume, complete };

// What a run will do, the same on every rank.
struct ExplorePlan {
    PlanMode mode = PlanMode::fresh;
    std::filesystem::path output;
    std::string note;  // for the user: what was decided and why (may be empty)
};

// Collective over `team` (run/team.hpp). Decides on the root what to do with the output (a
// result, written when the run completes) and its partial file (OUTPUT.partial, the run in
// progress), and tells every process. Throws InputError (on every process, same text) when
// they must not be touched: the output exists and neither --resume nor --overwrite says
// what to do with it, it is not a superball file (never replaced, even with --overwrite), it
// belongs to another job or version, or it cannot be written.
ExplorePlan plan_explore(const Job& job, const ExploreSettings& settings, const Team& team);

// What `superball explore --dry-run` shows: the run planned for `ranks` ranks, decided from
// the files there (run/files_there.hpp) without running it or changing a file: a pending
// undo log is not applied (the note says the run would apply it first), no directory is made.
// `plan`/`refusal`: plan_explore's decision; `files`: what is there, for batch scripts
// choosing between a new run and --resume.
struct DryRun {
    std::optional<ExplorePlan> plan;  // none: refused, for the reason in `refusal`
    std::string refusal;
    FilesThere files;
    Tiling tiling;
    std::uint32_t writers = 0;  // asked for (0: auto)
};
DryRun dry_run_explore(const Job& job, const ExploreSettings& settings, int ranks);

// The provenance of a run of `settings` starting now (job/provenance.hpp): settings.command
// (else this process's command line), the time, `ranks` on `hosts` with `threads` counting
// threads each, and the kernel.
Provenance run_provenance(const ExploreSettings& settings, int ranks, int hosts, int threads);

// How the schedule went, over every rank (the figures tests/scale/sim_run prints under the
// same names, which tests/scale/validate.sh --oversubscribed compares): `explore --stats`.
struct ScheduleFigures {
    int computing_ranks = 0;         // ranks that counted tiles (rank 0 only serves from 64 ranks)
    bool two_level = false;          // node leaders served their nodes
    std::uint64_t tiles = 0;         // tiles counted, every rank
    std::uint64_t tiles_min = 0;     // fewest tiles a computing rank counted
    std::uint64_t tiles_max = 0;     // most
    std::uint64_t root_blocks = 0;   // blocks rank 0 took from its pool
    std::uint64_t root_messages = 0; // messages rank 0 received
    std::uint64_t root_requests = 0; // of which requests for a block
    std::uint64_t root_asked_back = 0;     // requests for tiles back rank 0 sent
    std::uint64_t max_leader_messages = 0; // most messages another rank (a node leader) received
    std::uint64_t given_back = 0;    // tiles given back, every rank
    int writers = 1;                 // ranks that wrote compressed tiles (rank 0 and node leaders)
    std::uint64_t placed_max = 0;    // most tiles a writer other than rank 0 wrote
};

struct RunSummary {
    std::filesystem::path output;
    std::filesystem::path partial;   // where the run is kept until complete (OUTPUT.partial)
    bool complete = false;           // every tile done, the result closed complete
    bool interrupted = false;        // stopped on request (resumable)
    bool nothing_to_do = false;      // the output was already complete
    std::uint64_t points_this_run = 0;    // points of the tiles done by this run
    std::uint64_t points_counted = 0;     // of which counted by the kernel (fewer with refinement)
    std::vector<std::uint64_t> outcomes;  // histogram of this run's points by outcome code
    double compute_seconds = 0;           // from the first tile handed out to the last one done
    double finish_seconds = 0;            // from the last tile counted to the result under its name
    std::uint64_t raw_bytes = 0;          // of the data, uncompressed
    std::uint64_t result_bytes = 0;       // of the result file
    std::string sidecar_note;             // "sidecar: PATH", or why the result has none
    double peak_rss_mib = 0;              // largest over the ranks
    int ranks = 1;
    ScheduleFigures schedule;             // this run's
};

// Collective over `comm`: plans (plan_explore), runs and finishes the job. Returns on
// every rank; the summary's figures are valid on every rank. Throws InputError (every
// rank) when planning refuses, RunError (every rank) when the files cannot be made or
// finished; other exceptions mean the ranks may be out of step, and the caller should end
// them all (mpi::Comm::abort).
RunSummary run_explore(const Job& job, const ExploreSettings& settings, const mpi::Comm& comm, RunObserver& observer,
                       const StopRequested& stop);

}  // namespace superball
