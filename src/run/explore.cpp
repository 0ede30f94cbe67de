#include "explore.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <chrono>
#include <fstream>
#include <optional>
#include <system_error>
#include <utility>

#include "core/count.hpp"
#include "io/chunk_codec.hpp"
#include "io/final_result.hpp"
#include "io/result_metadata.hpp"
#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/placed_chunks.hpp"
#include "io/posix_file.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "job/provenance.hpp"
#include "run/explore_work.hpp"
#include "run/files_there.hpp"
#include "run/lifecycle.hpp"
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
Decision decide_partial(const ExploreSettings& s, const FoundFile& found, const Job& job)
{
    const fs::path& partial = found.path;
    std::string problem = found.problem;
    if (found.info && found.info->kind != FileKind::partial) problem = partial.string() + " is a complete result, not a partial file";
    if (!problem.empty()) {
        if (!found.info && !found.identity.superball) {
            return refuse_foreign(s, partial, found.identity, " (where this output's run keeps its tiles)");
        }
        if (s.overwrite) return {Verdict::fresh, "replacing " + partial.string() + ", which cannot be resumed (--overwrite)"};
        return refuse(problem + "; it is left as it is: --overwrite to start the run again, or --output to write elsewhere");
    }
    const ResultInfo& info = *found.info;
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
    const std::size_t bytes = count_bytes(job);
    if (info.shape != shape || info.count_bytes != bytes) {
        return refuse(fmt::format("{} is damaged: its data ({}, {}-bit counts) contradict its {} ({}, {}-bit "
                                  "counts); refusing to resume onto it: --overwrite to start again, or --output to write "
                                  "elsewhere",
                                  partial.string(), fmt::join(info.shape, " x "), 8 * info.count_bytes,
                                  layout::attr::job_fingerprint.name, fmt::join(shape, " x "), 8 * bytes));
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
Decision decide_output(const ExploreSettings& s, const FoundFile& found, const Job& job)
{
    const fs::path& out = found.path;
    if (!found.info) {
        if (!found.identity.superball) return refuse_foreign(s, out, found.identity, "");
        if (s.overwrite) return {Verdict::fresh, "replacing the damaged " + out.string() + " (--overwrite)"};
        return refuse(found.problem + "; --overwrite to replace it, or --output to write elsewhere");
    }
    const ResultInfo& info = *found.info;
    if (info.kind != FileKind::result) {
        if (s.overwrite) return {Verdict::fresh, "replacing " + out.string() + ", the partial file of a run (--overwrite)"};
        return refuse(fmt::format("{} holds the partial file of a run ({} of {} tiles done), not a result; --overwrite "
                                  "to replace it, or --output to write elsewhere",
                                  out.string(), info.tiles_done, info.tiles));
    }
    if (s.overwrite) return {Verdict::fresh, "replacing " + out.string() + " when the new run completes (--overwrite)"};
    if (!s.resume) {
        return refuse(out.string() + " already holds a complete result; use --overwrite to replace it or --output to "
                                     "write elsewhere");
    }
    if (info.job_fingerprint != fingerprint(job)) {
        return refuse(out.string() + " holds the result of a different job (grid, model or max_bounces differ): use "
                                     "another --output, or --overwrite");
    }
    return {Verdict::complete, out.string() + " is already complete: nothing to do"};
}

// Rank 0: the other files a run writes, the sidecar OUTPUT.xmf and the undo log
// OUTPUT.partial.undo (io/placed_chunks.hpp), are replaced only if they are superball's too.
std::optional<Decision> check_companions(const ExploreSettings& s, const FilesThere& files)
{
    if (files.undo_log.exists && !files.undo_log.ours) {
        return refuse_foreign(s, files.undo_log.path, files.undo_log.identity,
                              " (where the run keeps the undo log of its partial file's changes)");
    }
    if (files.gets_sidecar && files.sidecar.exists && !files.sidecar.ours) {
        return refuse_foreign(s, files.sidecar.path, files.sidecar.identity, " (where the result's ParaView sidecar goes)");
    }
    return std::nullopt;
}

// Rank 0, for a fresh run, before anything is written: the output's directory exists
// (created if need be) and files can be made there. A path that cannot be written is
// refused like bad input (status 2, one message) instead of failing later on every rank.
Decision cannot_write(const fs::path& out, const std::string& why)
{
    return refuse("cannot write the result " + out.string() + ": " + why + "; choose another --output (or [run] output)");
}

Decision check_writable(const fs::path& out, Decision d)
{
    const auto cannot = [&](const std::string& why) { return cannot_write(out, why); };
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

// check_writable for --dry-run, which makes nothing: the nearest directory that exists on
// the output's path must let this process make files in it.
Decision check_writable_as_is(const fs::path& out, Decision d)
{
    std::error_code ec;
    if (fs::is_directory(out, ec)) return cannot_write(out, "it is a directory");
    fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
    while (!fs::exists(dir, ec) && dir.has_parent_path() && dir.parent_path() != dir) dir = dir.parent_path();
    if (!fs::is_directory(dir, ec)) return cannot_write(out, dir.string() + " is not a directory");
    if (::access(dir.c_str(), W_OK | X_OK) != 0) {
        return cannot_write(out, "cannot make files in " + dir.string() + " (" +
                                     std::error_code(errno, std::generic_category()).message() + ")");
    }
    return d;
}

// What to do, from the files there alone: nothing is changed.
Decision decide(const ExploreSettings& s, const FilesThere& files, const Job& job)
{
    if (std::optional<Decision> d = check_companions(s, files)) return *d;
    if (files.partial.exists) return decide_partial(s, files.partial, job);
    if (files.output.exists) return decide_output(s, files.output, job);
    return {Verdict::fresh, s.resume ? "no run to resume at " + files.output.path.string() + ": starting a new run" : ""};
}

// Rank 0, before a run: the files there looked at, the undo log (superball's: another file
// there is refused by decide) of a run that stopped while finishing applied first (its partial file as it was before: io/placed_chunks.hpp) and that
// of a run that finished discarded, the decision made, and a fresh run's output checked
// writable.
Decision prepare(const ExploreSettings& s, const fs::path& out, const Job& job)
{
    FilesThere files = look_at_files(out);
    std::string undone;
    std::error_code ec;
    if (!files.partial.exists) {
        if (files.undo_log.ours) PlacedChunks::discard_undo(files.partial.path);
    } else if (files.undo_log.ours && fs::is_regular_file(files.partial.path, ec) &&
               PlacedChunks::undo_interrupted_changes(files.partial.path)) {
        undone = "the run before stopped while finishing " + files.partial.path.string() + ": its changes were undone; ";
        files.partial = look_at(files.partial.path);
    }
    Decision d = decide(s, files, job);
    d.message = undone + d.message;
    return d.verdict == Verdict::fresh ? check_writable(out, std::move(d)) : d;
}

}  // namespace

StartedPartial start_partial(const fs::path& partial, PlanMode mode, const Job& job, const Grid& grid, int ranks,
                             const Provenance& provenance)
{
    StartedPartial p;
    try {
        if (mode == PlanMode::fresh) {
            const Tiling tiling = default_tiling(job, ranks);
            p.tile_shape = tiling.tile_shape();
            p.layout = create_partial(partial, job, grid, tiling, provenance);
            p.done.assign(tiling.tiles(), 0);
        } else {
            const ResultReader reader(partial);
            p.tile_shape = reader.info().tile_shape;
            p.layout = partial_layout(partial, Tiling(grid.shape(), p.tile_shape));
            p.done = reader.tiles_done();
            p.earlier_seconds = reader.info().wall_seconds;
        }
    } catch (const std::exception& e) {
        throw RunError(fmt::format("{} {} failed ({}){}", mode == PlanMode::fresh ? "creating" : "reading", partial.string(),
                                   e.what(), free_space_note(partial)));
    }
    return p;
}

// Not larger: a rank waits at the end of its run for its last buffer to reach the file
// system, and with 8 MiB that wait cost a quarter of `explore -n 2`'s speed on the 4096^2
// slice (1.54e8 against 2.03e8 points/s, medians of 5 interleaved runs); 2 MiB was no
// faster and made more than 3 write calls per million points at 8192^2.
std::uint64_t tile_writer_bytes(const Job& job) { return std::max<std::uint64_t>(std::uint64_t{4} << 20, job.alignment); }

std::uint64_t handout_granule(const Job& job, const PartialLayout& layout)
{
    return layout.compressed ? 1 : std::max<std::uint64_t>(1, job.alignment / layout.counts_chunk());
}

RunSummary first_summary(const ExplorePlan& plan, int ranks)
{
    RunSummary summary;
    summary.output = plan.output;
    summary.partial = layout::partial_path(plan.output);
    summary.ranks = ranks;
    summary.outcomes.assign(outcome_count, 0);
    return summary;
}

double seconds_since(std::chrono::steady_clock::time_point t)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

FinishReport record_or_finish(const ClosingRun& run, std::span<const std::uint8_t> done, bool interrupted,
                              RunObserver& observer)
{
    try {
        const double seconds = seconds_since(run.started);
        if (interrupted) {
            record_partial_run(run.partial, seconds, run.provenance);
            return {};
        }
        observer.finishing();
        return finish_result(run.partial, run.output, result_info(run.job, run.grid), run.tiling, run.layout, done,
                             {run.provenance, run.earlier_seconds + seconds, true});
    } catch (const std::exception& e) {
        throw RunError(fmt::format("{} {} failed: {}", interrupted ? "recording the run in" : "finishing the result from",
                                   run.partial.string(), e.what()));
    }
}

InputError damaged_partial(const fs::path& partial, std::span<const std::uint64_t> bad, std::uint64_t done)
{
    return InputError(fmt::format("{} is damaged: {} of its {} done tiles (first: tile {}) no longer match the checksum "
                                  "written with them; refusing to resume onto it: --overwrite to start again, or --output "
                                  "to write elsewhere",
                                  partial.string(), bad.size(), done, bad.front()));
}

double peak_rss_mib()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_maxrss) / 1024.0;
}

namespace {

// Counts tiles and hands them on: compressed, into a batch that goes to rank 0 with the
// rank's reports (TileWork::flush); uncompressed, to the rank's TileWriter.
class Work final : public ExploreWork {
public:
    Work(const Job& job, const Grid& grid, const Tiling& tiling, const PartialLayout& layout, TileWriter* writer, CountKernel k)
        : job_(job),
          grid_(grid),
          tiling_(tiling),
          layout_(layout),
          writer_(writer),
          counter_(kernel_for(grid, k), job.max_bounces)
    {
        if (layout.compressed) encoder_.emplace(static_cast<int>(layout.level));
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
        if (writer_) {
            writer_->add(t, counts_, outcomes_);
        } else {
            compress(t);
        }
        points += starts_.size();
        add_to_histogram(outcomes_);
    }

    Flushed flush() override
    {
        if (writer_) return {writer_->flush(), {}};
        Flushed f{batch_.reports(), batch_.pack()};
        batch_.clear();
        return f;
    }

    // A rank's compressed tiles leave at least every 4 MiB.
    bool should_flush() const override { return batch_.data.size() >= (std::size_t{4} << 20); }

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

    std::vector<std::uint64_t> tallies() const override
    {
        std::vector<std::uint64_t> t = histogram;
        t.insert(t.end(), {counted, points});
        return t;
    }

    std::vector<std::uint64_t> histogram = std::vector<std::uint64_t>(outcome_count, 0);
    std::uint64_t counted = 0;  // points counted by the kernel (fewer than the tiles' with refinement)
    std::uint64_t points = 0;

private:
    // The tile's chunks as the result stores them, from memory, once: into the batch.
    void compress(std::uint64_t t)
    {
        const std::span<const std::uint32_t> c = in_chunk_layout<std::uint32_t>(tiling_, t, counts_, chunk_counts_);
        const std::span<const std::uint8_t> o = in_chunk_layout<std::uint8_t>(tiling_, t, outcomes_, chunk_outcomes_);
        const std::size_t at = batch_.data.size();
        const std::size_t cb = encoder_->counts(c, layout_.count_bytes, batch_.data);
        const std::size_t ob = encoder_->outcomes(o, batch_.data);
        const std::span<const std::byte> stored(batch_.data.data() + at, cb + ob);
        batch_.entries.insert(batch_.entries.end(), {t, tile_checksum(t, stored.first(cb), stored.subspan(cb)), cb, ob});
    }

    const Job& job_;
    const Grid& grid_;
    const Tiling& tiling_;
    const PartialLayout& layout_;
    TileWriter* writer_;
    std::optional<ChunkEncoder> encoder_;
    TileBatch batch_;
    TileCounter counter_;
    Starts starts_;
    std::vector<ModelRun> runs_;
    std::vector<std::uint32_t> counts_, chunk_counts_;
    std::vector<std::uint8_t> outcomes_, chunk_outcomes_;
};

// Rank 0's append buffer, and a writer's: 8 MiB, or a stripe if larger.
std::uint64_t append_buffer_bytes(const Job& job) { return std::max<std::uint64_t>(std::uint64_t{8} << 20, job.alignment); }

// A node leader writing compressed tiles (run/work_pool.hpp, TileSink): its own, its node's
// and those passed aside to it, into the file space rank 0 grants it, a stripe ahead.
class AppenderSink final : public TileSink {
public:
    AppenderSink(PartialFile& file, const Job& job)
        : appender_(file, ChunkAppender::Granted{job.alignment}, append_buffer_bytes(job))
    {
    }
    void add(std::span<const TileReport> tiles, std::span<const std::byte> payload) override
    {
        appender_.add(batch_of(tiles, payload));
    }
    std::uint64_t wanted() const override { return appender_.wanted(); }
    void grant(std::uint64_t address, std::uint64_t bytes) override { appender_.grant(address, bytes); }
    std::vector<AppendedTile> written() override { return appender_.written(); }
    bool holding() const override { return appender_.holding(); }
    bool full() const override { return appender_.full(); }

private:
    ChunkAppender appender_;
};

}  // namespace

std::unique_ptr<ExploreWork> make_explore_work(const Job& job, const Grid& grid, const Tiling& tiling,
                                               const PartialLayout& layout, TileWriter* writer, CountKernel kernel)
{
    return std::make_unique<Work>(job, grid, tiling, layout, writer, kernel);
}

Provenance run_provenance(const ExploreSettings& settings, int ranks, int hosts, int threads)
{
    return {settings.command.empty() ? process_command_line() : settings.command, utc_now(), ranks, hosts, threads,
            describe(settings.kernel)};
}

fs::path output_path(const Job& job, const ExploreSettings& settings)
{
    fs::path out = settings.output.empty() ? fs::path(job.output) : settings.output;
    if (out.empty()) throw InputError("no output file: set [run] output in the job or give --output");
    return out;
}

TileBatch batch_of(std::span<const TileReport> tiles, std::span<const std::byte> payload)
{
    TileBatch batch = TileBatch::unpack(payload);
    const std::vector<TileReport> carried = batch.reports();
    if (carried.size() != tiles.size() || !std::equal(carried.begin(), carried.end(), tiles.begin(), [](auto& a, auto& b) {
            return a.tile == b.tile && a.checksum == b.checksum;
        })) {
        throw std::logic_error("explore: the tiles a rank sent differ from those it reported");
    }
    return batch;
}

Recorder::Recorder(PartialFile& file, const fs::path& partial, std::vector<std::uint8_t> done, const Job& job,
                   const PartialLayout& layout, const Tiling& tiling, RunObserver& observer, int writers)
    : partial_(partial), tiling_(tiling), observer_(observer),
      record_(file, std::move(done), std::chrono::duration<double>(job.checkpoint_seconds))
{
    if (!layout.compressed) return;
    // Alone, the tiles follow one another from the file's end exactly as they come; with
    // several writers every grant is whole stripes, rank 0's own asked a stripe ahead like
    // the others'.
    if (writers <= 1) {
        appender_.emplace(file, file.file().size(), append_buffer_bytes(job));
        return;
    }
    unit_ = job.alignment;
    next_free_ = (file.file().size() + unit_ - 1) / unit_ * unit_;
    appender_.emplace(file, ChunkAppender::Granted{unit_}, append_buffer_bytes(job));
}

FileSpace Recorder::grant(std::uint64_t bytes)
{
    const FileSpace f{next_free_, (bytes + unit_ - 1) / unit_ * unit_};
    next_free_ += f.bytes;
    return f;
}

template <class Tile>
void Recorder::tell(std::span<const Tile> tiles)
{
    std::uint64_t points = 0;
    for (const Tile& t : tiles) points += tiling_.box(t.tile).points();
    if (!tiles.empty()) observer_.tiles_done(tiles.size(), points);
}

void Recorder::done(std::span<const TileReport> tiles, std::span<const std::byte> payload)
{
    if (appender_) {
        // Rank 0 grants itself its file space first (several writers), so that the batch is
        // placed as it comes.
        const TileBatch batch = batch_of(tiles, payload);
        const auto grant_own = [&](std::uint64_t bytes) {
            const FileSpace f = grant(bytes);
            appender_->grant(f.address, f.bytes);
        };
        if (const std::uint64_t w = appender_->wanted(batch.data.size())) grant_own(w);
        appender_->add(batch);
        while (const std::uint64_t w = appender_->wanted()) grant_own(w);  // range ends too short for a tile
        recorded(appender_->written());
    } else {
        record_.record(tiles);
        tell(tiles);
    }
    if (record_.due()) checkpoint();
}

void Recorder::placed(std::span<const AppendedTile> tiles)
{
    recorded(tiles);
    if (record_.due()) checkpoint();
}

// Between two checkpoints the partial file is a consistent HDF5 file holding every tile it
// records. (The write in progress is waited for: tiles are recorded once written, and a
// tile written a moment ago would otherwise wait a whole report period for the next call.)
void Recorder::checkpoint()
{
    if (appender_) recorded(appender_->flush());
    if (record_.checkpoint(true) && appender_) PlacedChunks::cover(partial_);
}

void Recorder::last()
{
    if (appender_) recorded(appender_->flush());
    record_.checkpoint(true);
}

void Recorder::recorded(std::span<const AppendedTile> tiles)
{
    record_.record(tiles);
    tell(tiles);
}

namespace {

// prepare(), which never throws: whatever goes wrong, every rank must hear the verdict.
Decision decide_or_refuse(const ExploreSettings& settings, const fs::path& out, const Job& job)
{
    try {
        return prepare(settings, out, job);
    } catch (const std::exception& e) {
        return refuse("cannot decide what to do with " + out.string() + ": " + e.what());
    }
}

ExplorePlan plan_of(const Decision& d, const fs::path& out)
{
    if (d.verdict == Verdict::refuse) throw InputError(d.message);
    const PlanMode mode = d.verdict == Verdict::fresh ? PlanMode::fresh
                          : d.verdict == Verdict::resume ? PlanMode::resume
                                                         : PlanMode::complete;
    return {mode, out, d.message};
}

}  // namespace

ExplorePlan plan_explore(const Job& job, const ExploreSettings& settings, const Team& team)
{
    const fs::path out = output_path(job, settings);
    Decision d;
    if (team.is_root()) d = decide_or_refuse(settings, out, job);
    d.verdict = static_cast<Verdict>(team.broadcast(static_cast<std::int64_t>(d.verdict)));
    d.message = team.broadcast(std::move(d.message));
    return plan_of(d, out);
}

namespace {

// Collective: every rank's ScheduleStats reduced to the run's figures (rank 0's own where
// they are a server's). Four small reductions at the end of a run.
ScheduleFigures schedule_figures(const mpi::Comm& comm, const ScheduleStats& mine)
{
    const bool root = comm.is_root();
    const std::vector<std::uint64_t> sums =
        comm.sum({mine.computed ? 1u : 0u, mine.given_back, root ? mine.handed_out.size() : 0u, root ? mine.messages_in : 0u,
                  root ? mine.requests_in : 0u, root ? mine.asked_back : 0u, root && mine.two_level ? 1u : 0u, mine.tiles});
    // Maxima as doubles (exact below 2^53): the most tiles, minus the fewest, the leaders' messages.
    const double most = comm.max(mine.computed ? static_cast<double>(mine.tiles) : 0.0);
    const double fewest = -comm.max(mine.computed ? -static_cast<double>(mine.tiles) : -most);
    const double leader_messages = comm.max(root ? 0.0 : static_cast<double>(mine.messages_in));
    ScheduleFigures f;
    f.computing_ranks = static_cast<int>(sums[0]);
    f.given_back = sums[1];
    f.root_blocks = sums[2];
    f.root_messages = sums[3];
    f.root_requests = sums[4];
    f.root_asked_back = sums[5];
    f.two_level = sums[6] != 0;
    f.tiles = sums[7];
    f.tiles_max = static_cast<std::uint64_t>(most);
    f.tiles_min = static_cast<std::uint64_t>(fewest);
    f.max_leader_messages = static_cast<std::uint64_t>(leader_messages);
    f.writers = mine.writers;
    f.placed_max = static_cast<std::uint64_t>(comm.max(static_cast<double>(mine.tiles_placed)));
    return f;
}

}  // namespace

Counted count_on_ranks(OpenRun& run, std::vector<ListedTile> pending, const ExploreSettings& settings,
                       const StopRequested& stop)
{
    const mpi::Comm& comm = *run.team.comm();
    const Job& job = run.job;
    const PartialLayout& layout = run.start.layout;
    // Several writers: rank 0 records where the others wrote and grants them file space;
    // each rank but 0 holds a sink, used if the schedule makes it a writer.
    std::optional<AppenderSink> sink;
    Writers writing;
    if (run.writers > 1 && comm.is_root()) {
        writing.placed = [&](std::span<const AppendedTile> tiles) { run.recorder->placed(tiles); };
        writing.grant = [&](std::uint64_t bytes) { return run.recorder->grant(bytes); };
    } else if (run.writers > 1) {
        writing.sink = &sink.emplace(run.file, job);
    }
    // Uncompressed tiles: each rank writes its own.
    std::optional<TileWriter> writer;
    if (!layout.compressed) writer.emplace(run.file, tile_writer_bytes(job));
    Work work(job, run.grid, run.tiling, layout, writer ? &*writer : nullptr, settings.kernel);
    const TilesDone on_done = [&](std::span<const TileReport> tiles, int, std::span<const std::byte> payload) {
        run.recorder->done(tiles, payload);
    };
    ScheduleSettings schedule = schedule_settings(settings, job);
    schedule.granule = handout_granule(job, layout);
    // Every rank holds the hand-out list through the run (4 bytes a tile): made in place
    // from what is left, not beside it.
    pending = handout_order(std::move(pending), schedule.granule, comm.size() >= settings.interleave_ranks);
    const auto compute_start = std::chrono::steady_clock::now();
    const ScheduleResult r = run_schedule(comm, pending, work, on_done, stop, schedule, writing);
    Counted c{r.interrupted, work.tallies(), 0, std::chrono::steady_clock::now(), schedule_figures(comm, r.stats)};
    c.compute_seconds = comm.broadcast(std::chrono::duration<double>(c.end - compute_start).count());
    return c;
}

DryRun dry_run_explore(const Job& job, const ExploreSettings& settings, int ranks)
{
    const fs::path out = output_path(job, settings);
    DryRun d{std::nullopt, {}, look_at_files(out), default_tiling(job, ranks), settings.writers.value_or(job.writers)};
    Decision decision = decide(settings, d.files, job);
    if (d.files.partial.exists && d.files.undo_log.ours) {
        decision.message = "the run before stopped while finishing " + d.files.partial.path.string() +
                           ": a run undoes its changes first, then decides again; " + decision.message;
    }
    if (decision.verdict == Verdict::fresh) decision = check_writable_as_is(out, std::move(decision));
    if (decision.verdict == Verdict::refuse) {
        d.refusal = decision.message;
    } else {
        d.plan = plan_of(decision, out);
    }
    return d;
}

RunSummary run_explore(const Job& job, const ExploreSettings& settings, const mpi::Comm& comm, RunObserver& observer,
                       const StopRequested& stop)
{
    return run_lifecycle(job, settings, Team::ranks(comm), observer, stop);
}

}  // namespace superball
