#include "explore_threads.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>

#include "io/partial_file.hpp"
#include "job/grid.hpp"
#include "run/explore_work.hpp"
#include "run/lifecycle.hpp"
#include "run/threads.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {


// Counts `pending` on one thread per work: each takes the next `granule` tiles (an
// alignment unit of an uncompressed file's tiles, so that a thread's writer joins them into
// one write; else one tile) until none is left or a stop is asked for, and hands its tiles
// to `done` (one call at a time) at least every `report_seconds` and when its work says so.
// Returns whether the run was stopped with tiles left undone.
bool count_tiles(std::span<const ListedTile> pending, std::span<const std::unique_ptr<ExploreWork>> works,
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

// The works' tallies (ExploreWork::tallies), summed.
std::vector<std::uint64_t> tallies_of(std::span<const std::unique_ptr<ExploreWork>> works)
{
    std::vector<std::uint64_t> totals(outcome_count + 2, 0);
    for (const auto& w : works) {
        const std::vector<std::uint64_t> t = w->tallies();
        for (std::size_t k = 0; k < totals.size(); ++k) totals[k] += t[k];
    }
    return totals;
}

}  // namespace

Counted count_on_threads(OpenRun& run, std::vector<ListedTile> pending, const ExploreSettings& settings,
                         const StopRequested& stop)
{
    const ThreadWorks works = make_works(run.team.threads_each(), run.job, run.grid, run.file, settings.kernel);
    const auto on_done = [&](const Flushed& f) { run.recorder->done(f.reports, f.payload); };
    const std::uint64_t granule = handout_granule(run.job, run.start.layout);
    const auto compute_start = std::chrono::steady_clock::now();
    Counted c;
    c.interrupted = count_tiles(pending, works.works, granule, ScheduleSettings{}.report_seconds, on_done, stop);
    c.end = std::chrono::steady_clock::now();
    c.compute_seconds = std::chrono::duration<double>(c.end - compute_start).count();
    c.tallies = tallies_of(works.works);
    return c;
}

RunSummary run_explore_threads(const Job& job, const ExploreSettings& settings, unsigned threads, RunObserver& observer,
                               const StopRequested& stop)
{
    return run_lifecycle(job, settings, Team::threads(threads == 0 ? usable_cores() : threads), observer, stop);
}

}  // namespace superball
