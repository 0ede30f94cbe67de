#include "explore_threads.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>

#include "io/final_result.hpp"
#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/placed_chunks.hpp"
#include "io/posix_file.hpp"
#include "io/result_metadata.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "run/explore_work.hpp"
#include "run/threads.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {


// Counts `pending` on one thread per work: each takes the next `granule` tiles (an
// alignment unit of an uncompressed file's tiles, so that a thread's writer joins them into
// one write; else one tile) until none is left or a stop is asked for, and hands its tiles
// to `done` (one call at a time) at least every `report_seconds` and when its work says so.
// Returns whether the run was stopped with tiles left undone.
bool count_tiles(std::span<const std::uint64_t> pending, std::span<const std::unique_ptr<ExploreWork>> works,
                 std::uint64_t granule, double report_seconds, const std::function<void(Flushed)>& done,
                 const StopRequested& stop)
{
    std::atomic<std::size_t> next{0}, computed{0};
    std::atomic<bool> stopping{false};
    std::mutex m;
    const auto hand_over = [&](TileWork& w) {
        Flushed f = w.flush();
        if (f.reports.empty()) return;
        const std::lock_guard lock(m);
        done(std::move(f));
    };
    run_on_threads(static_cast<unsigned>(works.size()), [&](unsigned i) {
        TileWork& w = *works[i];
        auto reported = std::chrono::steady_clock::now();
        bool last = false;
        // A thread that fails (a write, say) stops the others at their next tile.
        struct StopOthers {
            std::atomic<bool>& stopping;
            ~StopOthers()
            {
                if (std::uncaught_exceptions() > 0) stopping = true;
            }
        } stop_others{stopping};
        while (!last) {
            const std::size_t first = next.fetch_add(granule);
            last = first >= pending.size();
            for (std::size_t k = first; k < std::min<std::size_t>(first + granule, pending.size()); ++k) {
                // Only the calling thread asks: a Python signal handler runs on no other.
                if (i == 0 && stop && stop()) stopping = true;
                if (stopping) {
                    last = true;
                    break;
                }
                w.compute(pending[k], Serve{});
                ++computed;
                if (w.should_flush() || seconds_since(reported) >= report_seconds) {
                    hand_over(w);
                    reported = std::chrono::steady_clock::now();
                }
            }
        }
        hand_over(w);
    });
    return computed.load() < pending.size();
}

// The tiles done and those left to compute, once the done ones are checked against the
// checksums written with them.
std::pair<std::vector<std::uint64_t>, std::vector<std::uint64_t>> tiles_left(PartialFile& file, const fs::path& partial,
                                                                             std::span<const std::uint8_t> done,
                                                                             const Tiling& tiling)
{
    std::vector<std::uint64_t> done_tiles, pending;
    const auto done_count = static_cast<std::uint64_t>(std::count(done.begin(), done.end(), std::uint8_t{1}));
    done_tiles.reserve(done_count);
    pending.reserve(tiling.tiles() - done_count);
    for (std::uint64_t t = 0; t < tiling.tiles(); ++t) (done[t] == 0 ? pending : done_tiles).push_back(t);
    const JournalRecord record = read_journal(file, done_tiles);
    if (const std::vector<std::uint64_t> bad = file.damaged(done_tiles, record.checksums, record.stored); !bad.empty()) {
        file.close();
        throw damaged_partial(partial, bad, done_tiles.size());
    }
    return {std::move(done_tiles), std::move(pending)};
}

// One work a thread, with its writer of uncompressed tiles (compressed ones go to the
// recorder, as rank 0's do).
struct ThreadWorks {
    std::vector<std::optional<TileWriter>> writers;
    std::vector<std::unique_ptr<ExploreWork>> works;
};

ThreadWorks make_works(unsigned threads, const Job& job, const Grid& grid, PartialFile& file, CountKernel kernel)
{
    ThreadWorks t;
    t.writers.resize(threads);
    const PartialLayout& layout = file.layout();
    for (std::optional<TileWriter>& w : t.writers) {
        if (!layout.compressed) w.emplace(file, tile_writer_bytes(job));
        t.works.push_back(make_explore_work(job, grid, file.tiling(), layout, w ? &*w : nullptr, kernel));
    }
    return t;
}

// The works' tallies (ExploreWork::tallies), summed, into the summary.
void add_tallies(RunSummary& summary, std::span<const std::unique_ptr<ExploreWork>> works)
{
    std::vector<std::uint64_t> totals(outcome_count + 2, 0);
    for (const auto& w : works) {
        const std::vector<std::uint64_t> t = w->tallies();
        for (std::size_t k = 0; k < totals.size(); ++k) totals[k] += t[k];
    }
    summary.points_this_run = totals[outcome_count + 1];
    summary.points_counted = totals[outcome_count];
    summary.outcomes.assign(totals.begin(), totals.begin() + outcome_count);
}

}  // namespace

RunSummary run_explore_threads(const Job& job, const ExploreSettings& settings, unsigned threads, RunObserver& observer,
                               const StopRequested& stop)
{
    const auto started = std::chrono::steady_clock::now();
    if (threads == 0) threads = usable_cores();
    const ExplorePlan plan = plan_explore(job, settings);
    const Provenance provenance = run_provenance(settings, 1, 1, static_cast<int>(threads));
    const fs::path partial = layout::partial_path(plan.output);
    RunSummary summary = first_summary(plan, 1);
    if (plan.mode == PlanMode::complete) {
        observer.started({plan.output, plan.note, 1, job.points(), 0, 0, 0, 0});
        summary.complete = summary.nothing_to_do = true;
        return summary;
    }

    // The partial file and its journal, as run_explore makes or reads them; the tiling of a
    // new file is the one `mpirun -n THREADS` would choose.
    const Grid grid(job);
    auto [tile_shape, layout, done, earlier_seconds] =
        start_partial(partial, plan.mode, job, grid, static_cast<int>(threads), provenance);
    const Tiling tiling(grid.shape(), tile_shape);
    PartialFile file(partial, tiling, layout);
    const auto [done_tiles, pending] = tiles_left(file, partial, done, tiling);
    RunStart start{plan.output, plan.note, 1, job.points(), tiling.tiles(), tiling.box(0).points(), done_tiles.size(), 0};
    for (const std::uint64_t t : done_tiles) start.points_done += tiling.box(t).points();
    observer.started(start);

    // The writer side, as rank 0's: the journal, and one appender of compressed tiles.
    Recorder recorder(file, partial, std::move(done), job, layout, tiling, observer);
    const ThreadWorks works = make_works(threads, job, grid, file, settings.kernel);
    const auto on_done = [&](const Flushed& f) { recorder.done(f.reports, f.payload); };
    const std::uint64_t granule = handout_granule(job, layout);
    const auto compute_start = std::chrono::steady_clock::now();
    const bool interrupted = count_tiles(pending, works.works, granule, ScheduleSettings{}.report_seconds, on_done, stop);
    const auto compute_end = std::chrono::steady_clock::now();
    summary.compute_seconds = std::chrono::duration<double>(compute_end - compute_start).count();
    observer.computed(summary.compute_seconds);

    try {
        interrupted ? recorder.checkpoint() : recorder.last();
    } catch (const std::exception& e) {
        throw RunError(e.what());
    }
    file.close();
    const FinishReport finish = record_or_finish({job, grid, tiling, layout, partial, plan.output, provenance, earlier_seconds,
                                                  started},
                                                 recorder.journal().done(), interrupted, observer);
    if (!interrupted) {
        summary.finish_seconds = seconds_since(compute_end);
        summary.raw_bytes = finish.raw_bytes;
        summary.result_bytes = finish.file_bytes;
        summary.sidecar_note = finish.sidecar_note;
    }
    add_tallies(summary, works.works);
    summary.peak_rss_mib = peak_rss_mib();
    summary.interrupted = interrupted;
    summary.complete = !interrupted;
    return summary;
}

}  // namespace superball
