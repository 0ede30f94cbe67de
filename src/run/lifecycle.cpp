#include "lifecycle.hpp"

#include <fmt/core.h>

#include <bit>
#include <string>
#include <utility>

#include "io/final_result.hpp"
#include "io/layout.hpp"
#include "io/stored_tiles.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {

PartialLayout broadcast(const Team& team, const PartialLayout& l)
{
    const std::vector<std::uint64_t> v =
        team.broadcast(std::vector<std::uint64_t>{l.compressed ? 1u : 0u, l.level, l.counts_at, l.outcomes_at, l.done_at,
                                                  l.checksums_at, l.stored_at, l.count_bytes, l.chunk_points, l.tiles});
    return {v[0] != 0, v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]};
}

// What the root found or made (start_partial), on every process; a failure on the root
// thrown on every process.
StartedPartial start_everywhere(const Team& team, const fs::path& partial, PlanMode mode, const Job& job, const Grid& grid,
                                const Provenance& provenance)
{
    StartedPartial started;
    team.root_acts([&] { started = start_partial(partial, mode, job, grid, team.counters(), provenance); });
    started.tile_shape = team.broadcast(std::move(started.tile_shape));
    started.layout = broadcast(team, started.layout);
    return started;
}

// The threads of one process share one descriptor, opened at once; a rank opens the file
// only if it uses it.
PartialFile open_partial(const Team& team, const fs::path& partial, const Tiling& tiling, const PartialLayout& layout)
{
    if (team.comm()) return {partial, tiling, layout, PartialFile::OnFirstUse{}};
    return {partial, tiling, layout};
}

// The tiles left to count and how many are done, on every process, and their points on the
// root, which reports them (from the root's journal). A resume first checks that the done
// tiles still hold what was written: each process checks a share, and is sent only its
// share's checksums and places, which the root reads from the journal a share at a time
// (every rank holding all of them, 40 bytes a done tile, was the most memory a rank of a
// resume at thousands of ranks took; rank 0 holding all of them at once, 32:
// tests/scale/README.md).
struct TilesLeft {
    std::vector<ListedTile> pending;
    std::uint64_t done = 0;
    std::uint64_t points_done = 0;  // on the root
};

// Whether tile t's done flag is set in `bits` (a bit a tile).
bool flagged(const std::vector<std::uint64_t>& bits, std::uint64_t t) { return ((bits[t / 64] >> (t % 64)) & 1u) != 0; }

// A share's record as one message: its checksums, then (compressed) where each tile lies.
std::vector<std::uint64_t> words_of(const JournalRecord& r)
{
    std::vector<std::uint64_t> words = r.checksums;
    for (const StoredChunk& c : r.stored) words.insert(words.end(), {c.address, c.counts_bytes, c.outcomes_bytes});
    return words;
}

JournalRecord record_of(const std::vector<std::uint64_t>& words, std::size_t tiles, bool compressed)
{
    JournalRecord r;
    r.checksums.assign(words.begin(), words.begin() + static_cast<std::ptrdiff_t>(tiles));
    for (std::size_t i = 0; compressed && i < tiles; ++i) {
        const std::size_t at = tiles + 3 * i;
        r.stored.push_back({words[at], words[at + 1], words[at + 2]});
    }
    return r;
}

// The done tiles of this process's share, with their record: the root reads each share
// from the journal and sends it to its process (one message a process), keeping its own.
std::pair<std::vector<std::uint64_t>, JournalRecord> my_share(OpenRun& run, const TilesLeft& left,
                                                              const std::vector<std::uint64_t>& bits)
{
    const Team& team = run.team;
    const auto is_done = [&](std::uint64_t t) { return flagged(bits, t); };
    // Process r checks the done tiles [n r / P, n (r + 1) / P) of the n in order.
    const auto processes = static_cast<std::uint64_t>(team.processes());
    const auto share_begin = [&](std::uint64_t r) { return left.done * r / processes; };
    constexpr int tag_share = 31;  // before the schedule: no other message is in flight
    const bool compressed = run.file.layout().compressed;
    std::vector<std::uint64_t> mine;
    JournalRecord record;
    if (team.is_root()) {
        // One pass over the done tiles: each share sent as soon as it is whole.
        std::vector<std::uint64_t> share;
        std::uint64_t r = 0;
        const auto pass_on = [&] {
            if (r == 0) {
                record = read_journal(run.file, share);
                mine = std::move(share);
            } else {
                team.send(words_of(read_journal(run.file, share)), static_cast<int>(r), tag_share);
            }
            share.clear();
            ++r;
        };
        for (std::uint64_t t = 0; t < run.tiling.tiles(); ++t) {
            if (!is_done(t)) continue;
            while (share_begin(r) + share.size() == share_begin(r + 1)) pass_on();
            share.push_back(t);
        }
        while (r < processes) pass_on();
    } else {
        const auto rank = static_cast<std::uint64_t>(team.rank());
        for (std::uint64_t t = 0, i = 0; t < run.tiling.tiles() && i < share_begin(rank + 1); ++t) {
            if (is_done(t) && i++ >= share_begin(rank)) mine.push_back(t);
        }
        record = record_of(team.receive(mine.size() * (compressed ? 4 : 1), 0, tag_share), mine.size(), compressed);
    }
    return {std::move(mine), std::move(record)};
}

TilesLeft tiles_left(OpenRun& run)
{
    const Team& team = run.team;
    const Tiling& tiling = run.tiling;
    if (tiling.tiles() > max_run_tiles) {  // a file no run of this version makes (default_tiling)
        throw InputError(fmt::format("{} holds {} tiles: a run takes at most {}", run.partial.string(), tiling.tiles(),
                                     max_run_tiles));
    }
    // The done flags, a bit a tile.
    std::vector<std::uint64_t> bits;
    if (team.is_root()) {
        const std::vector<std::uint8_t>& done = run.start.done;
        bits.assign((done.size() + 63) / 64, 0);
        for (std::uint64_t t = 0; t < done.size(); ++t) bits[t / 64] |= std::uint64_t{done[t] != 0} << (t % 64);
    }
    bits = team.broadcast(std::move(bits));
    TilesLeft left;
    for (const std::uint64_t word : bits) left.done += static_cast<std::uint64_t>(std::popcount(word));
    // Reserved: grown by doubling, the list would take up to three times its size while it
    // is built (50 MiB for 16 MiB of it at 2 million tiles).
    left.pending.reserve(tiling.tiles() - left.done);
    for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
        if (!flagged(bits, t)) {
            left.pending.push_back(static_cast<ListedTile>(t));
        } else if (team.is_root()) {
            left.points_done += tiling.box(t).points();
        }
    }
    if (run.plan.mode != PlanMode::resume) return left;
    const auto [mine, record] = my_share(run, left, bits);
    if (const std::vector<std::uint64_t> bad = team.all_of(run.file.damaged(mine, record.checksums, record.stored));
        !bad.empty()) {
        run.file.close();
        throw damaged_partial(run.partial, bad, left.done);
    }
    return left;
}

// What the run's note says of its writers when they are not what was asked: `asked` (0:
// auto) for a compressed file, `writers` chosen.
std::string writers_note(int asked, int writers, const PartialLayout& layout)
{
    if (!layout.compressed && asked > 1) {
        return "every rank writes its own tiles to an uncompressed result ([run] compression = 0): writers = " +
               std::to_string(asked) + " does not apply";
    }
    if (asked <= writers) return "";
    return fmt::format("{} writers asked, {} write{}: writers are rank 0 and node leaders, at most one per node "
                       "(--node-ranks N makes nodes of N ranks on one machine)",
                       asked, writers, writers == 1 ? "s" : "");
}

std::string join_notes(const std::string& a, const std::string& b)
{
    return a.empty() ? b : b.empty() ? a : a + "; " + b;
}

// Before counting: who writes (a team of ranks' schedule decides), the root's observer
// told what the run does, and the root's recorder made.
void begin_counting(OpenRun& run, const TilesLeft& left, const ExploreSettings& settings)
{
    const Team& team = run.team;
    const PartialLayout& layout = run.start.layout;
    std::string note = run.plan.note;
    if (const mpi::Comm* comm = team.comm()) {
        const ScheduleSettings schedule = schedule_settings(settings, run.job);
        run.writers = layout.compressed ? schedule_writers(*comm, schedule) : 1;
        note = join_notes(note, writers_note(schedule.writers, run.writers, layout));
    }
    if (!team.is_root()) return;
    run.observer.started({run.plan.output, note, team.processes(), run.job.points(), run.tiling.tiles(),
                          run.tiling.box(0).points(), left.done, left.points_done});
    run.recorder.emplace(run.file, run.partial, std::move(run.start.done), run.job, layout, run.tiling, run.observer,
                         run.writers);
}

// What the root does with the partial file once the tiles are counted: an interrupted run's
// seconds recorded in it, a complete run's result made from it. A failure on the root is
// thrown on every process.
FinishReport close_run(OpenRun& run, bool interrupted)
{
    const Team& team = run.team;
    FinishReport finish;
    std::optional<Failure> failure;
    if (team.is_root()) failure = attempt([&] { interrupted ? run.recorder->checkpoint() : run.recorder->last(); });
    // The run's figures, in the partial file (a stop) or the result (complete), by the root
    // alone once every process has closed the file.
    run.file.close();
    team.barrier();
    if (team.is_root() && !failure) {
        failure = attempt([&] {
            finish = record_or_finish({run.job, run.grid, run.tiling, run.start.layout, run.partial, run.plan.output,
                                       run.provenance, run.start.earlier_seconds, run.started},
                                      run.recorder->journal().done(), interrupted, run.observer);
        });
    }
    team.throw_everywhere(failure);
    return finish;
}

// The summary's figures of a run counted and closed, on every process.
void summarize(RunSummary& summary, const Team& team, const Counted& counted, const FinishReport& finish)
{
    if (!counted.interrupted) {
        // From the last tile counted to the result under its name.
        summary.finish_seconds = team.broadcast(team.is_root() ? seconds_since(counted.end) : 0.0);
        summary.raw_bytes = static_cast<std::uint64_t>(team.broadcast(static_cast<std::int64_t>(finish.raw_bytes)));
        summary.result_bytes = static_cast<std::uint64_t>(team.broadcast(static_cast<std::int64_t>(finish.file_bytes)));
        summary.sidecar_note = team.broadcast(finish.sidecar_note);
    }
    std::vector<std::uint64_t> totals = team.sum(counted.tallies);  // with the histogram: one reduction
    summary.points_this_run = totals.back();
    totals.pop_back();
    summary.points_counted = totals.back();
    totals.pop_back();
    summary.outcomes = std::move(totals);
    summary.compute_seconds = counted.compute_seconds;
    summary.peak_rss_mib = team.max(peak_rss_mib());
    summary.schedule = counted.figures;
    summary.interrupted = counted.interrupted;
    summary.complete = !counted.interrupted;
}

}  // namespace

OpenRun::OpenRun(const Team& team, const Job& job, const ExplorePlan& plan, const Provenance& provenance,
                 RunObserver& observer, std::chrono::steady_clock::time_point started)
    : team(team),
      job(job),
      plan(plan),
      provenance(provenance),
      observer(observer),
      started(started),
      partial(layout::partial_path(plan.output)),
      grid(job),
      start(start_everywhere(team, partial, plan.mode, job, grid, provenance)),
      tiling(grid.shape(), start.tile_shape),
      file(open_partial(team, partial, tiling, start.layout))
{
}

ScheduleSettings schedule_settings(const ExploreSettings& settings, const Job& job)
{
    ScheduleSettings schedule;
    schedule.node_ranks = settings.node_ranks;
    schedule.writers = static_cast<int>(settings.writers.value_or(job.writers));
    return schedule;
}

RunSummary run_lifecycle(const Job& job, const ExploreSettings& settings, const Team& team, RunObserver& observer,
                         const StopRequested& stop)
{
    const auto started = std::chrono::steady_clock::now();
    const ExplorePlan plan = plan_explore(job, settings, team);
    const Provenance provenance =
        run_provenance(settings, team.processes(), team.hosts(), static_cast<int>(team.threads_each()));
    RunSummary summary = first_summary(plan, team.processes());
    if (plan.mode == PlanMode::complete) {
        if (team.is_root()) observer.started({plan.output, plan.note, team.processes(), job.points(), 0, 0, 0, 0});
        summary.complete = summary.nothing_to_do = true;
        return summary;
    }

    OpenRun run(team, job, plan, provenance, observer, started);
    TilesLeft left = tiles_left(run);
    begin_counting(run, left, settings);
    const Counted counted = team.comm() ? count_on_ranks(run, std::move(left.pending), settings, stop)
                                        : count_on_threads(run, std::move(left.pending), settings, stop);
    if (team.is_root()) observer.computed(counted.compute_seconds);
    summarize(summary, team, counted, close_run(run, counted.interrupted));
    return summary;
}

}  // namespace superball
