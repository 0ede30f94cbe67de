#include "explore.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <utility>
#include <system_error>

#include "core/count.hpp"
#include "io/result_file.hpp"
#include "io/xdmf.hpp"
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

// Rank 0: what to do with the output path.
Decision decide(const ExploreSettings& s, const fs::path& out, const Job& job)
{
    std::error_code ec;
    if (!fs::exists(out, ec)) {
        return {Verdict::fresh, s.resume ? "no result at " + out.string() + " to resume: starting a new run" : ""};
    }
    if (s.overwrite) return {Verdict::fresh, "replacing " + out.string() + " (--overwrite)"};
    ResultInfo info;
    try {
        info = read_result_info(out);
    } catch (const std::exception& e) {
        return {Verdict::refuse, out.string() + " exists and is not a readable superball result (" + e.what() +
                                     "); it is left alone: choose another --output, or --overwrite to replace it"};
    }
    if (!s.resume) {
        if (info.complete) {
            return {Verdict::refuse, out.string() + " already holds a complete result; use --overwrite to replace it or "
                                                    "--output to write elsewhere"};
        }
        return {Verdict::refuse, fmt::format("{} holds an interrupted run ({} of {} tiles done); add --resume to finish it "
                                             "or --overwrite to start again",
                                             out.string(), info.tiles_done, info.tiles)};
    }
    if (info.job_fingerprint != fingerprint(job)) {
        return {Verdict::refuse, out.string() + " was made by a different job (grid, model or max_bounces differ); "
                                                "refusing to mix results: use another --output, or --overwrite"};
    }
    if (info.software_version != software_version) {
        return {Verdict::refuse, fmt::format("{} was made by superball {}, this is {}; refusing to mix results of two "
                                             "versions: use another --output, or --overwrite",
                                             out.string(), info.software_version, software_version)};
    }
    // Never build on done tiles whose bytes changed on disk since they were written (nor
    // call such a file complete).
    try {
        if (const std::vector<std::uint64_t> bad = damaged_tiles(out); !bad.empty()) {
            return {Verdict::refuse, fmt::format("{} is damaged: {} of its {} done tiles (first: tile {}) no longer match the "
                                                 "checksum written with them; refusing to resume onto it: --overwrite to "
                                                 "start again, or --output to write elsewhere",
                                                 out.string(), bad.size(), info.tiles_done, bad.front())};
        }
    } catch (const std::exception& e) {
        return {Verdict::refuse, out.string() + " cannot be read back (" + e.what() +
                                     "); refusing to resume onto it: --overwrite to start again, or --output to write elsewhere"};
    }
    if (info.complete) return {Verdict::complete, out.string() + " is already complete: nothing to do"};
    return {Verdict::resume, fmt::format("resuming {}: {} of {} tiles already done", out.string(), info.tiles_done, info.tiles)};
}

// Rank 0, for a fresh run, before anything is written: the output's directory exists
// (created if need be) and a file can be made there. A path that cannot be written is
// refused like bad input (status 2, one message) instead of failing in the collective
// HDF5 create on every rank (status 1 through MPI_Abort, and no reason given).
Decision check_writable(const fs::path& out, Decision d)
{
    const auto refuse = [&](const std::string& why) {
        return Decision{Verdict::refuse, "cannot write the result " + out.string() + ": " + why +
                                             "; choose another --output (or [run] output)"};
    };
    std::error_code ec;
    if (out.has_parent_path()) {
        fs::create_directories(out.parent_path(), ec);
        if (ec) return refuse("cannot create its directory " + out.parent_path().string() + " (" + ec.message() + ")");
    }
    // Opened for writing without truncation (--overwrite replaces the file later, collectively).
    const bool existed = fs::exists(out, ec);
    const int fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) return refuse(std::error_code(errno, std::generic_category()).message());
    ::close(fd);
    if (!existed) fs::remove(out, ec);
    return d;
}

// Peak resident memory of this process, in MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_maxrss) / 1024.0;
}

CountKernel kernel_for(const Grid& grid, CountKernel k)
{
    return grid.on_boundary_plane() ? &count_each_on_plane : k;
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
        d = decide(settings, out, job);
        if (d.verdict == Verdict::fresh) d = check_writable(out, std::move(d));
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
    RunSummary summary;
    summary.output = plan.output;
    summary.ranks = comm.size();
    summary.outcomes.assign(outcome_count, 0);
    if (plan.mode == PlanMode::complete) {
        if (comm.is_root()) observer.started({plan.output, plan.note, comm.size(), job.points(), 0, 0, 0, 0});
        summary.complete = summary.nothing_to_do = true;
        return summary;
    }

    const Grid grid(job);
    ResultFile file = plan.mode == PlanMode::fresh
                          ? ResultFile::create(plan.output, comm, job, grid, default_tiling(job, comm.size()))
                          : ResultFile::open(plan.output, comm);
    const Tiling& tiling = file.tiling();

    std::vector<std::uint64_t> pending;
    if (comm.is_root()) {
        RunStart start{plan.output, plan.note, comm.size(), job.points(), tiling.tiles(), tiling.box(0).points(), 0, 0};
        const std::vector<std::uint8_t> done = file.tiles_done();
        for (std::uint64_t t = 0; t < done.size(); ++t) {
            if (done[t]) {
                ++start.tiles_done;
                start.points_done += tiling.box(t).points();
            } else {
                pending.push_back(t);
            }
        }
        observer.started(start);
    }
    comm.broadcast(pending);

    // Counts a tile and writes it at once (TileWork).
    class Work final : public TileWork {
    public:
        Work(const Job& job, const Grid& grid, ResultFile& file, CountKernel k)
            : job_(job), grid_(grid), file_(file), counter_(kernel_for(grid, k), job.max_bounces)
        {
        }
        void compute(std::uint64_t t, const Serve& serve) override
        {
            const Box box = file_.tiling().box(t);
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
            file_.write_tile(t, counts_, outcomes_);
            points += starts_.size();
            for (const std::uint8_t o : outcomes_) ++histogram[o];
            reports_.push_back({t, 0});
        }
        std::vector<TileReport> flush() override { return std::exchange(reports_, {}); }

        std::vector<std::uint64_t> histogram = std::vector<std::uint64_t>(outcome_count, 0);
        std::uint64_t counted = 0;  // points counted by the kernel (fewer than the tiles' with refinement)
        std::uint64_t points = 0;

    private:
        const Job& job_;
        const Grid& grid_;
        ResultFile& file_;
        TileCounter counter_;
        Starts starts_;
        std::vector<ModelRun> runs_;
        std::vector<std::uint32_t> counts_;
        std::vector<std::uint8_t> outcomes_;
        std::vector<TileReport> reports_;
    } work(job, grid, file, settings.kernel);
    const TilesDone on_done = [&](std::span<const TileReport> tiles, int) {
        std::uint64_t points = 0;
        for (const TileReport& r : tiles) points += tiling.box(r.tile).points();
        observer.tiles_done(tiles.size(), points);
    };
    const auto compute_start = std::chrono::steady_clock::now();
    const ScheduleResult r = run_schedule(comm, pending, work, on_done, stop);
    const double compute_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - compute_start).count();
    if (comm.is_root()) observer.computed(compute_seconds);

    // Attributes are written collectively and must be identical on every rank.
    const double run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    file.finish(comm.broadcast(run_seconds), comm.size(), !r.interrupted);
    std::vector<std::uint64_t> histogram = work.histogram;
    histogram.push_back(work.counted);  // summed with the histogram: one reduction
    histogram.push_back(work.points);
    std::vector<std::uint64_t> total = comm.sum(histogram);
    summary.points_this_run = total.back();
    total.pop_back();
    summary.points_counted = total.back();
    total.pop_back();
    summary.outcomes = std::move(total);
    summary.compute_seconds = comm.broadcast(compute_seconds);
    summary.peak_rss_mib = comm.max(peak_rss_mib());
    summary.interrupted = r.interrupted;
    summary.complete = !r.interrupted;
    if (comm.is_root()) write_xdmf(plan.output, read_result_info(plan.output));
    return summary;
}

}  // namespace superball
