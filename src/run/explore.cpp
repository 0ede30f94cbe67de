#include "explore.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <optional>
#include <system_error>
#include <utility>

#include "core/count.hpp"
#include "io/final_result.hpp"
#include "io/result_metadata.hpp"
#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/posix_file.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "run/refine.hpp"
#include "run/tile_counter.hpp"
#include "superball/version.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {

enum class Verdict : std::int64_t { fresh, resume, complete, refuse };

struct Decision {
    Verdict verdict = Verdict::fresh;
    std::string message;  // why a run is refused, or a note
};

Decision refuse(std::string why) { return {Verdict::refuse, std::move(why)}; }

// Why a file that is not superball's stays where it is: --overwrite replaces superball's
// files only (a thesis, a directory, another program's HDF5 file are never replaced), and
// the refusal suggests the flag only where it would help.
Decision refuse_foreign(const ExploreSettings& s, const fs::path& path, const FileIdentity& id, std::string_view role)
{
    return refuse(fmt::format("{} exists{} and is {}: not a superball file, and superball replaces only its own files{}; "
                              "move it away or choose another --output",
                              path.string(), role, id.description, s.overwrite ? ", even with --overwrite" : ""));
}

// Rank 0: what to do with an existing partial file (a run in progress or interrupted).
Decision decide_partial(const ExploreSettings& s, const fs::path& partial, const Job& job)
{
    std::optional<ResultReader> reader;
    std::string problem;
    try {
        reader.emplace(partial);
        if (reader->info().kind != FileKind::partial) problem = partial.string() + " is a complete result, not a partial file";
    } catch (const InputError& e) {
        problem = e.what();
    }
    if (!problem.empty()) {
        const FileIdentity id = identify_file(partial);
        if (!id.superball) return refuse_foreign(s, partial, id, " (where this output's run keeps its tiles)");
        if (s.overwrite) return {Verdict::fresh, "replacing " + partial.string() + ", which cannot be resumed (--overwrite)"};
        return refuse(problem + "; it is left as it is: --overwrite to start the run again, or --output to write elsewhere");
    }
    const ResultInfo& info = reader->info();
    if (s.overwrite) {
        return {Verdict::fresh, fmt::format("replacing the interrupted run in {} ({} of {} tiles done; --overwrite)",
                                            partial.string(), info.tiles_done, info.tiles)};
    }
    if (!s.resume) {
        return refuse(fmt::format("{} holds an interrupted run of this output ({} of {} tiles done); add --resume to "
                                  "finish it or --overwrite to start again",
                                  partial.string(), info.tiles_done, info.tiles));
    }
    if (info.job_fingerprint != fingerprint(job)) {
        return refuse(partial.string() + " was made by a different job (grid, model or max_bounces differ); refusing to mix "
                                         "results: use another --output, or --overwrite");
    }
    // The resume writes tiles at offsets computed from the job's grid: a file whose data
    // disagree with its own fingerprint is not written to.
    const Extent shape = Grid(job).shape();
    const std::size_t count_bytes = H5Tget_size(count_type(job));
    if (info.shape != shape || info.count_bytes != count_bytes) {
        return refuse(fmt::format("{} is damaged: its data ({}, {}-bit counts) contradict its job_fingerprint ({}, {}-bit "
                                  "counts); refusing to resume onto it: --overwrite to start again, or --output to write "
                                  "elsewhere",
                                  partial.string(), fmt::join(info.shape, " x "), 8 * info.count_bytes,
                                  fmt::join(shape, " x "), 8 * count_bytes));
    }
    if (info.software_version != software_version) {
        return refuse(fmt::format("{} was made by superball {}, this is {}; refusing to mix results of two versions: use "
                                  "another --output, or --overwrite",
                                  partial.string(), info.software_version, software_version));
    }
    return {Verdict::resume, fmt::format("resuming {}: {} of {} tiles already done", partial.string(), info.tiles_done,
                                         info.tiles)};
}

// Rank 0: what to do with an existing output and no partial file.
Decision decide_output(const ExploreSettings& s, const fs::path& out, const Job& job)
{
    try {
        const ResultReader reader(out);
        const ResultInfo& info = reader.info();
        if (info.kind != FileKind::result) {
            if (s.overwrite) return {Verdict::fresh, "replacing " + out.string() + ", the partial file of a run (--overwrite)"};
            return refuse(fmt::format("{} holds the partial file of a run ({} of {} tiles done), not a result; --overwrite "
                                      "to replace it, or --output to write elsewhere",
                                      out.string(), info.tiles_done, info.tiles));
        }
        if (s.overwrite) {
            return {Verdict::fresh, "replacing " + out.string() + " when the new run completes (--overwrite)"};
        }
        if (!s.resume) {
            return refuse(out.string() + " already holds a complete result; use --overwrite to replace it or --output to "
                                         "write elsewhere");
        }
        if (info.job_fingerprint != fingerprint(job)) {
            return refuse(out.string() + " holds the result of a different job (grid, model or max_bounces differ): use "
                                         "another --output, or --overwrite");
        }
        return {Verdict::complete, out.string() + " is already complete: nothing to do"};
    } catch (const InputError& e) {
        const FileIdentity id = identify_file(out);
        if (!id.superball) return refuse_foreign(s, out, id, "");
        if (s.overwrite) return {Verdict::fresh, "replacing the damaged " + out.string() + " (--overwrite)"};
        return refuse(std::string(e.what()) + "; --overwrite to replace it, or --output to write elsewhere");
    }
}

// Whether `path` is an XDMF sidecar as superball writes them (io/xdmf.cpp): XML naming a
// result's /wall_bounces. A sidecar is small; the first 64 KiB say.
bool is_superball_sidecar(const fs::path& path)
{
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return false;
    std::ifstream in(path, std::ios::binary);
    std::string head(64 * 1024, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    return head.rfind("<?xml", 0) == 0 && head.find("<Xdmf") != std::string::npos &&
           head.find(":/wall_bounces</DataItem>") != std::string::npos;
}

// Rank 0: the other files a run writes, OUTPUT.finishing (the result before it takes its
// name) and the sidecar OUTPUT.xmf, are replaced only if they are superball's too.
std::optional<Decision> check_companions(const ExploreSettings& s, const fs::path& out)
{
    const fs::path sidecar = layout::sidecar_path(out);
    std::error_code ec;
    const fs::path finishing = layout::finishing_path(out);
    if (fs::exists(finishing, ec) || fs::is_symlink(finishing, ec)) {
        const FileIdentity id = identify_file(finishing);
        if (!id.superball) return refuse_foreign(s, finishing, id, " (where the result is written before it takes its name)");
    }
    // A result named *.xmf, or with a colon in its name, gets no sidecar (xdmf_unsupported).
    const bool gets_sidecar = sidecar != out && out.filename().string().find(':') == std::string::npos;
    if (gets_sidecar && (fs::exists(sidecar, ec) || fs::is_symlink(sidecar, ec))) {
        if (!is_superball_sidecar(sidecar)) {
            return refuse_foreign(s, sidecar, identify_file(sidecar), " (where the result's ParaView sidecar goes)");
        }
    }
    return std::nullopt;
}

// Rank 0, for a fresh run, before anything is written: the output's directory exists
// (created if need be) and files can be made there. A path that cannot be written is
// refused like bad input (status 2, one message) instead of failing later on every rank.
Decision check_writable(const fs::path& out, Decision d)
{
    const auto cannot = [&](const std::string& why) {
        return refuse("cannot write the result " + out.string() + ": " + why + "; choose another --output (or [run] output)");
    };
    std::error_code ec;
    if (out.has_parent_path()) {
        fs::create_directories(out.parent_path(), ec);
        if (ec) return cannot("cannot create its directory " + out.parent_path().string() + " (" + ec.message() + ")");
    }
    if (fs::is_directory(out, ec)) return cannot("it is a directory");
    const fs::path partial = layout::partial_path(out);
    const bool existed = fs::exists(partial, ec);
    const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) return cannot(std::error_code(errno, std::generic_category()).message());
    ::close(fd);
    if (!existed) fs::remove(partial, ec);
    return d;
}

Decision decide(const ExploreSettings& s, const fs::path& out, const Job& job)
{
    if (std::optional<Decision> d = check_companions(s, out)) return *d;
    std::error_code ec;
    const fs::path partial = layout::partial_path(out);
    if (fs::exists(partial, ec) || fs::is_symlink(partial, ec)) {
        Decision d = decide_partial(s, partial, job);
        return d.verdict == Verdict::fresh ? check_writable(out, std::move(d)) : d;
    }
    if (fs::exists(out, ec) || fs::is_symlink(out, ec)) {
        Decision d = decide_output(s, out, job);
        return d.verdict == Verdict::fresh ? check_writable(out, std::move(d)) : d;
    }
    return check_writable(out, {Verdict::fresh, s.resume ? "no run to resume at " + out.string() + ": starting a new run" : ""});
}

// Peak resident memory of this process, in MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_maxrss) / 1024.0;
}

void broadcast(const mpi::Comm& comm, PartialLayout& l)
{
    std::vector<std::uint64_t> v{l.counts_at, l.outcomes_at, l.done_at, l.checksums_at, l.count_bytes, l.chunk_points, l.tiles};
    comm.broadcast(v);
    l = {v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
}

// Counts tiles and hands them to the writer (TileWork).
class Work final : public TileWork {
public:
    Work(const Job& job, const Grid& grid, TileWriter& writer, const Tiling& tiling, CountKernel k)
        : job_(job), grid_(grid), writer_(writer), tiling_(tiling), counter_(kernel_for(grid, k), job.max_bounces)
    {
    }

    void compute(std::uint64_t t, const Serve& serve) override
    {
        const Box box = tiling_.box(t);
        grid_.starts(box, starts_);
        grid_.model_runs(box, runs_);
        counts_.resize(starts_.size());
        outcomes_.resize(starts_.size());
        if (job_.refine != 0) {
            const CountPoints some = [&](std::span<const std::uint64_t> points) {
                counter_.some(points, starts_, runs_, counts_, outcomes_, serve);
            };
            counted += refine_tile(box.count, job_.refine, some, counts_, outcomes_);
        } else {
            counter_.all(starts_, runs_, counts_, outcomes_, serve);
            counted += starts_.size();
        }
        writer_.add(t, counts_, outcomes_);
        points += starts_.size();
        add_to_histogram(outcomes_);
    }

    std::vector<TileReport> flush() override { return writer_.flush(); }

    // The four codes from three sums the compiler vectorises (bit 0, bit 1, both bits):
    // 16 bytes or more per instruction instead of a counter increment per point, which
    // was a third of a run's time outside the kernel on the benchmark slice.
    void add_to_histogram(std::span<const std::uint8_t> outcomes)
    {
        static_assert(outcome_count == 4, "two bits per outcome code");
        std::uint64_t bit0 = 0, bit1 = 0, both = 0;
        // Blocks of at most 255 points: each sum fits the 8-bit lanes it is gathered in.
        for (std::size_t i = 0; i < outcomes.size(); i += 255) {
            const std::size_t end = std::min(outcomes.size(), i + 255);
            std::uint8_t b0 = 0, b1 = 0, bb = 0;
            for (std::size_t j = i; j < end; ++j) {
                const std::uint8_t o = outcomes[j];
                b0 = static_cast<std::uint8_t>(b0 + (o & 1u));
                b1 = static_cast<std::uint8_t>(b1 + ((o >> 1) & 1u));
                bb = static_cast<std::uint8_t>(bb + (o & (o >> 1) & 1u));
            }
            bit0 += b0;
            bit1 += b1;
            both += bb;
        }
        const std::uint64_t n = outcomes.size();
        histogram[3] += both;
        histogram[2] += bit1 - both;
        histogram[1] += bit0 - both;
        histogram[0] += n - bit0 - bit1 + both;
    }

    std::vector<std::uint64_t> histogram = std::vector<std::uint64_t>(outcome_count, 0);
    std::uint64_t counted = 0;  // points counted by the kernel (fewer than the tiles' with refinement)
    std::uint64_t points = 0;

private:
    const Job& job_;
    const Grid& grid_;
    TileWriter& writer_;
    const Tiling& tiling_;
    TileCounter counter_;
    Starts starts_;
    std::vector<ModelRun> runs_;
    std::vector<std::uint32_t> counts_;
    std::vector<std::uint8_t> outcomes_;
};

double seconds_since(std::chrono::steady_clock::time_point t)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

fs::path output_path(const Job& job, const ExploreSettings& settings)
{
    fs::path out = settings.output.empty() ? fs::path(job.output) : settings.output;
    if (out.empty()) throw InputError("no output file: set [run] output in the job or give --output");
    return out;
}

ExplorePlan plan_explore(const Job& job, const ExploreSettings& settings, const mpi::Comm& comm)
{
    const fs::path out = output_path(job, settings);
    Decision d;
    if (comm.is_root()) {
        // Whatever goes wrong here, every rank must hear the verdict.
        try {
            d = decide(settings, out, job);
        } catch (const std::exception& e) {
            d = refuse("cannot decide what to do with " + out.string() + ": " + e.what());
        }
    }
    d.verdict = static_cast<Verdict>(comm.broadcast(static_cast<std::int64_t>(d.verdict)));
    comm.broadcast(d.message);
    if (d.verdict == Verdict::refuse) throw InputError(d.message);
    const PlanMode mode = d.verdict == Verdict::fresh ? PlanMode::fresh
                          : d.verdict == Verdict::resume ? PlanMode::resume
                                                         : PlanMode::complete;
    return {mode, out, d.message};
}

RunSummary run_explore(const Job& job, const ExploreSettings& settings, const mpi::Comm& comm, RunObserver& observer,
                       const StopRequested& stop)
{
    const auto started = std::chrono::steady_clock::now();
    const ExplorePlan plan = plan_explore(job, settings, comm);
    const fs::path partial = layout::partial_path(plan.output);
    RunSummary summary;
    summary.output = plan.output;
    summary.ranks = comm.size();
    summary.outcomes.assign(outcome_count, 0);
    if (plan.mode == PlanMode::complete) {
        if (comm.is_root()) observer.started({plan.output, plan.note, comm.size(), job.points(), 0, 0, 0, 0});
        summary.complete = summary.nothing_to_do = true;
        return summary;
    }

    // The partial file and its journal: made by rank 0 (a new run) or read (a resume).
    const Grid grid(job);
    Extent tile_shape;
    PartialLayout layout;
    std::vector<std::uint8_t> done;
    std::vector<std::uint64_t> checksums;
    std::int64_t failed = 0;
    std::string failure;
    if (comm.is_root()) {
        try {
            if (plan.mode == PlanMode::fresh) {
                const Tiling tiling = default_tiling(job, comm.size());
                tile_shape = tiling.tile_shape();
                layout = create_partial(partial, job, grid, tiling, comm.size());
                done.assign(tiling.tiles(), 0);
                checksums.assign(tiling.tiles(), 0);
            } else {
                const ResultReader reader(partial);
                tile_shape = reader.info().tile_shape;
                layout = partial_layout(partial, Tiling(grid.shape(), tile_shape));
                done = reader.tiles_done();
                checksums = reader.tile_checksums();
            }
        } catch (const std::exception& e) {
            failed = 1;
            failure = fmt::format("{} {} failed ({}){}", plan.mode == PlanMode::fresh ? "creating" : "reading",
                                  partial.string(), e.what(), free_space_note(partial));
        }
    }
    if (comm.broadcast(failed) != 0) {
        comm.broadcast(failure);
        throw RunError(failure);
    }
    comm.broadcast(tile_shape);
    broadcast(comm, layout);
    const Tiling tiling(grid.shape(), tile_shape);
    PartialFile file(partial, comm, tiling, layout);

    // The tiles to compute, on every rank; a resume first checks the tiles already done.
    std::vector<std::uint64_t> done_tiles;
    for (std::uint64_t t = 0; t < done.size(); ++t) {
        if (done[t] != 0) done_tiles.push_back(t);
    }
    comm.broadcast(done_tiles);
    if (plan.mode == PlanMode::resume) {
        std::vector<std::uint64_t> sums;  // of the done tiles: rank 0 read them
        if (comm.is_root()) {
            for (const std::uint64_t t : done_tiles) sums.push_back(checksums[t]);
        }
        comm.broadcast(sums);
        if (const std::vector<std::uint64_t> bad = file.damaged(done_tiles, sums); !bad.empty()) {
            file.close();
            throw InputError(fmt::format("{} is damaged: {} of its {} done tiles (first: tile {}) no longer match the "
                                         "checksum written with them; refusing to resume onto it: --overwrite to start "
                                         "again, or --output to write elsewhere",
                                         partial.string(), bad.size(), done_tiles.size(), bad.front()));
        }
    }
    std::vector<std::uint64_t> pending;
    {
        std::uint64_t d = 0;
        for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
            if (d < done_tiles.size() && done_tiles[d] == t) {
                ++d;
            } else {
                pending.push_back(t);
            }
        }
    }
    std::optional<Journal> journal;
    if (comm.is_root()) {
        RunStart start{plan.output, plan.note, comm.size(), job.points(), tiling.tiles(), tiling.box(0).points(),
                       done_tiles.size(), 0};
        for (const std::uint64_t t : done_tiles) start.points_done += tiling.box(t).points();
        observer.started(start);
        journal.emplace(file, std::move(done), std::move(checksums), std::chrono::duration<double>(job.checkpoint_seconds));
    }

    // Writes leave in pieces of at least one alignment unit (and 4 MiB of counts), and
    // blocks of tiles are multiples of one where they can be, so that ranks rarely share a
    // stripe. Not larger: a rank waits at the end of its run for its last buffer to reach
    // the file system, and with 8 MiB that wait cost a quarter of `explore -n 2`'s speed on
    // the 4096^2 slice (1.54e8 against 2.03e8 points/s, medians of 5 interleaved runs); 2 MiB
    // was no faster and made more than 3 write calls per million points at 8192^2.
    const std::uint64_t buffer = std::max<std::uint64_t>(std::uint64_t{4} << 20, job.alignment);
    // The closing pass from memory (settings.closing_memory_ranks): decided alike on every
    // rank, from the grid alone.
    std::optional<RetainedTiles> kept;
    {
        // The largest share of the closing pass: whole result chunks, as many as the
        // rank with the most gets.
        const Tiling chunks = result_chunks(grid.shape());
        const auto ranks = static_cast<std::uint64_t>(comm.size());
        const std::uint64_t share = (chunks.tiles() + ranks - 1) / ranks * chunks.box(0).points() * (layout.count_bytes + 1);
        if (comm.size() >= settings.closing_memory_ranks && share <= settings.closing_memory_bytes / 2) {
            kept.emplace(layout.counts_chunk(), layout.outcomes_chunk(), settings.closing_memory_bytes / 2);
        }
    }
    TileWriter writer(file, buffer);
    if (kept) writer.retain(*kept);
    Work work(job, grid, writer, tiling, settings.kernel);
    const TilesDone on_done = [&](std::span<const TileReport> tiles, int) {
        journal->record(tiles);
        std::uint64_t points = 0;
        for (const TileReport& r : tiles) points += tiling.box(r.tile).points();
        observer.tiles_done(tiles.size(), points);
        journal->checkpoint(false);
    };
    ScheduleSettings schedule;
    schedule.granule = std::max<std::uint64_t>(1, job.alignment / layout.counts_chunk());
    pending = handout_order(pending, schedule.granule, comm.size() >= settings.interleave_ranks);
    const auto compute_start = std::chrono::steady_clock::now();
    const ScheduleResult r = run_schedule(comm, pending, work, on_done, stop, schedule);
    const double compute_seconds = comm.broadcast(seconds_since(compute_start));
    if (comm.is_root()) {
        observer.computed(compute_seconds);
        journal->checkpoint(true);
    }
    file.close();

    // The run's figures, in the partial file (a stop) or the result (complete).
    std::int64_t ok = 1;
    double total_seconds = 0;
    if (comm.is_root()) {
        try {
            total_seconds = record_partial_run(partial, seconds_since(started), comm.size());
        } catch (const std::exception& e) {
            ok = 0;
            failure = fmt::format("recording the run in {} failed: {}", partial.string(), e.what());
        }
    }
    if (comm.broadcast(ok) == 0) {
        comm.broadcast(failure);
        throw RunError(failure);
    }
    total_seconds = comm.broadcast(total_seconds);
    if (!r.interrupted) {
        if (comm.is_root()) observer.finishing();
        const Retained retained{kept ? &tiling : nullptr, kept ? &*kept : nullptr};
        const FinishReport f = write_result(partial, plan.output, job, grid, comm, {comm.size(), total_seconds, true}, retained);
        summary.finish_seconds = f.seconds;
        summary.raw_bytes = f.raw_bytes;
        summary.result_bytes = f.file_bytes;
        summary.sidecar_note = f.sidecar_note;
    }

    std::vector<std::uint64_t> totals = work.histogram;
    totals.push_back(work.counted);  // summed with the histogram: one reduction
    totals.push_back(work.points);
    totals = comm.sum(totals);
    summary.points_this_run = totals.back();
    totals.pop_back();
    summary.points_counted = totals.back();
    totals.pop_back();
    summary.outcomes = std::move(totals);
    summary.compute_seconds = compute_seconds;
    summary.peak_rss_mib = comm.max(peak_rss_mib());
    summary.interrupted = r.interrupted;
    summary.complete = !r.interrupted;
    return summary;
}

}  // namespace superball
