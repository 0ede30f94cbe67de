// superball explore: runs the job (run/explore.hpp) on every rank, prints the summary.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "explore_command.hpp"
#include "every_rank.hpp"
#include "core/count.hpp"
#include "core/kernels.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "mpi/mpi.hpp"
#include "run/explore.hpp"
#include "cli/terminal_progress.hpp"
#include "run/signals.hpp"

namespace superball::cli {

namespace fs = std::filesystem;

namespace {

void print_summary(const Job& job, const RunSummary& r, const KernelVariant& kernel)
{
    const double s = r.compute_seconds;
    const auto n = r.points_this_run;
    fmt::print(stderr, "{}: {} points computed in {:.2f} s ({:.3g} points/s), grid of {} points\n",
               r.complete ? "done" : "interrupted", n, s, s > 0 ? static_cast<double>(n) / s : 0.0, job.points());
    std::string line = "outcomes this run:";
    for (int o = 0; o < outcome_count; ++o) {
        const auto k = r.outcomes[static_cast<std::size_t>(o)];
        const double frac = n ? static_cast<double>(k) / static_cast<double>(n) : 0.0;
        line += fmt::format("  {} {} ({:.2f}%)", name(static_cast<Outcome>(o)), k, 100.0 * frac);
    }
    fmt::print(stderr, "{}\n", line);
    fmt::print(stderr, "peak memory per rank: {:.1f} MiB (largest rank)\n", r.peak_rss_mib);
    fmt::print(stderr, "counting kernel: {}\n", describe(kernel));
    if (r.complete && r.raw_bytes > 0) {
        fmt::print(stderr, "result: {} ({:.3g} MB, {:.2f}% of the {:.3g} MB of raw data; finished {:.3g} ms after the last "
                           "tile was counted)\n",
                   r.output.string(), static_cast<double>(r.result_bytes) / 1e6,
                   100.0 * static_cast<double>(r.result_bytes) / static_cast<double>(r.raw_bytes),
                   static_cast<double>(r.raw_bytes) / 1e6, 1e3 * r.finish_seconds);
    } else if (r.complete) {
        fmt::print(stderr, "result: {}\n", r.output.string());
    }
    if (!r.sidecar_note.empty()) fmt::print(stderr, "{}\n", r.sidecar_note);
    if (job.refine != 0) {
        fmt::print(stderr, "refinement: {} of {} points counted ({:.1f}%), the others filled from agreeing corners\n",
                   r.points_counted, n, 100.0 * static_cast<double>(r.points_counted) / static_cast<double>(std::max<std::uint64_t>(n, 1)));
    }
    if (r.interrupted) {
        fmt::print(stderr, "stopped {}: the run is kept in {} (consistent, {} not written yet); run the same command "
                           "with --resume to finish it\n",
                   StopSignals::which() != 0 ? "by a signal" : "after --stop-after seconds",
                   r.partial.string(), r.output.string());
    }
}

// What --stats prints: one line of key=value, the names tests/scale/sim_run gives the same
// figures (tests/scale/validate.sh --oversubscribed reads both).
void print_schedule(const ScheduleFigures& s)
{
    fmt::print(stderr,
               "schedule: tiles={} computing_ranks={} two_level={} tiles_min={} tiles_max={} root_blocks={} root_messages={} "
               "root_requests={} root_asked_back={} max_leader_messages={} given_back={} writers={} placed_max={}\n",
               s.tiles, s.computing_ranks, s.two_level ? 1 : 0, s.tiles_min, s.tiles_max, s.root_blocks, s.root_messages,
               s.root_requests, s.root_asked_back, s.max_leader_messages, s.given_back, s.writers, s.placed_max);
}

// What --dry-run prints: the validated job and dry_run_explore's plan, one `key: value` a
// line, for people and scripts.
void print_plan(const Job& job, const DryRun& d, int ranks)
{
    fmt::print("job: valid\ncoordinates: {}\n", name(job.coordinates));
    for (const Coordinate& p : job.parameters) {
        fmt::print("swept {}: {} samples in [{}, {}]\n", p.name, p.range->n, p.range->min, p.range->max);
    }
    for (const Coordinate& c : job.grid) {
        if (c.is_range()) {
            fmt::print("axis {}: {} samples in [{}, {}]\n", c.name, c.range->n, c.range->min, c.range->max);
        } else {
            fmt::print("fixed {}: {}\n", c.name, *c.fixed);
        }
    }
    fmt::print("model: {}\n", model_text(job.model));
    fmt::print("points: {}\nmax_bounces: {}\n", job.points(), job.max_bounces);
    if (job.refine != 0) fmt::print("refine: coarse stride {}\n", job.refine);
    if (Grid(job).on_boundary_plane()) fmt::print("boundary plane: xi = {} (limits from inside)\n", *job.grid[0].fixed);
    fmt::print("tiles: {} of up to {} points for {} rank{}\n", d.tiling.tiles(), d.tiling.box(0).points(), ranks,
               ranks == 1 ? "" : "s");
    if (job.compression == 0) {
        fmt::print("writers: every rank (uncompressed)\n");
    } else if (d.writers == 0) {
        fmt::print("writers: auto (one per node from 64 ranks on, else rank 0 alone)\n");
    } else {
        fmt::print("writers: {} (rank 0 and node leaders, at most one per node)\n", d.writers);
    }
    if (d.plan) {
        const char* mode = d.plan->mode == PlanMode::fresh ? "new run" : d.plan->mode == PlanMode::resume ? "resume" : "complete";
        fmt::print("plan: {}{}{}\n", mode, d.plan->note.empty() ? "" : ": ", d.plan->note);
    } else {
        fmt::print("plan: refused: {}\n", d.refusal);
    }
    // For batch scripts deciding between a new run and --resume: the result, or the partial
    // file of an interrupted run; then the other files a run writes, when something is there.
    const FilesThere& f = d.files;
    const bool exists = f.output.exists || f.partial.exists;
    fmt::print("output: {}\noutput exists: {}\n", f.output.path.string(), exists ? "yes" : "no");
    if (exists) {
        fmt::print("partial file: {}\n", f.partial.exists ? f.partial.path.string() : "none");
        const FoundFile& there = f.partial.exists ? f.partial : f.output;
        if (there.info) {
            fmt::print("output complete: {} ({} of {} tiles done)\noutput same job: {}\n",
                       there.info->kind == FileKind::result ? "yes" : "no", there.info->tiles_done, there.info->tiles,
                       there.info->job_fingerprint == fingerprint(job) ? "yes" : "no");
        } else {
            fmt::print("output complete: unreadable (not a superball result)\n");
        }
    }
    for (const auto& [name, c] : {std::pair{"undo log", &f.undo_log}, std::pair{"sidecar", &f.sidecar}}) {
        if (c->exists) fmt::print("{}: {} ({})\n", name, c->path.string(), c->ours ? "superball's" : c->identity.description);
    }
}

}  // namespace

int explore_command(const ExploreOptions& opt)
{
    // Before MPI starts: a signal during start-up then stops the run cleanly too.
    const StopSignals signals;
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    const bool root = world.is_root();
    return on_every_rank("explore", world, [&] {
        const KernelVariant& kernel = select_kernel(opt.kernel);
        const Job job = load_job(opt.job);
        ExploreSettings settings{opt.output, opt.resume, opt.overwrite, kernel.count};
        settings.node_ranks = opt.node_ranks;
        if (!opt.writers.empty()) settings.writers = writers_from_text(opt.writers, "--writers");
        if (opt.dry_run) {
            if (root) print_plan(job, dry_run_explore(job, settings, world.size()), world.size());
            return 0;
        }
        TerminalProgress progress(stderr, opt.quiet);
        const auto started = std::chrono::steady_clock::now();
        const StopRequested stop = [&] {
            return StopSignals::requested() ||
                   (opt.stop_after >= 0 &&
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() >= opt.stop_after);
        };
        const RunSummary r = run_explore(job, settings, world, progress, stop);
        if (root && !r.nothing_to_do) {
            print_summary(job, r, kernel);
            if (opt.stats) print_schedule(r.schedule);
        }
        return r.interrupted ? 1 : 0;
    });
}

}  // namespace superball::cli
