#include <fcntl.h>
#include <fmt/core.h>
#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "core/count.hpp"
#include "core/count_simd.hpp"
#include "explore/grid.hpp"
#include "explore/job.hpp"
#include "explore/mpi.hpp"
#include "explore/progress.hpp"
#include "explore/refine.hpp"
#include "explore/tile_counter.hpp"
#include "explore/schedule.hpp"
#include "explore/signals.hpp"
#include "io/result_file.hpp"
#include "io/xdmf.hpp"
#include "superball/version.hpp"

namespace superball::cli {

namespace fs = std::filesystem;

namespace {

struct ExploreOptions {
    std::string job;
    std::string output;
    bool resume = false;
    bool overwrite = false;
    bool quiet = false;
    bool dry_run = false;
    std::string kernel = "simd";
};

enum class Mode : std::int64_t { fresh, resume, complete, refuse };

// Rank 0 decides what to do with the output path; the others are told.
struct Decision {
    Mode mode = Mode::fresh;
    std::string message;  // why a run is refused, or a note
};

Decision decide(const ExploreOptions& opt, const fs::path& out, const Job& job)
{
    std::error_code ec;
    if (!fs::exists(out, ec)) {
        return {Mode::fresh, opt.resume ? "no result at " + out.string() + " to resume: starting a new run" : ""};
    }
    if (opt.overwrite) return {Mode::fresh, "replacing " + out.string() + " (--overwrite)"};
    ResultInfo info;
    try {
        info = read_result_info(out);
    } catch (const std::exception& e) {
        return {Mode::refuse, out.string() + " exists and is not a readable superball result (" + e.what() +
                                  "); it is left alone: choose another --output, or --overwrite to replace it"};
    }
    if (!opt.resume) {
        if (info.complete) {
            return {Mode::refuse, out.string() + " already holds a complete result; use --overwrite to replace it or "
                                                 "--output to write elsewhere"};
        }
        return {Mode::refuse, fmt::format("{} holds an interrupted run ({} of {} tiles done); add --resume to finish it "
                                          "or --overwrite to start again",
                                          out.string(), info.tiles_done, info.tiles)};
    }
    if (info.job_fingerprint != fingerprint(job)) {
        return {Mode::refuse, out.string() + " was made by a different job (grid, model or max_bounces differ); "
                                             "refusing to mix results: use another --output, or --overwrite"};
    }
    if (info.software_version != software_version) {
        return {Mode::refuse, fmt::format("{} was made by superball {}, this is {}; refusing to mix results of two "
                                          "versions: use another --output, or --overwrite",
                                          out.string(), info.software_version, software_version)};
    }
    // Never build on done tiles whose bytes changed on disk since they were written (nor
    // call such a file complete).
    try {
        if (const std::vector<std::uint64_t> bad = damaged_tiles(out); !bad.empty()) {
            return {Mode::refuse, fmt::format("{} is damaged: {} of its {} done tiles (first: tile {}) no longer match the "
                                              "checksum written with them; refusing to resume onto it: --overwrite to "
                                              "start again, or --output to write elsewhere",
                                              out.string(), bad.size(), info.tiles_done, bad.front())};
        }
    } catch (const std::exception& e) {
        return {Mode::refuse, out.string() + " cannot be read back (" + e.what() +
                                  "); refusing to resume onto it: --overwrite to start again, or --output to write elsewhere"};
    }
    if (info.complete) return {Mode::complete, out.string() + " is already complete: nothing to do"};
    return {Mode::resume, fmt::format("resuming {}: {} of {} tiles already done", out.string(), info.tiles_done, info.tiles)};
}

// Rank 0, for a fresh run, before anything is written: the output's directory exists
// (created if need be) and a file can be made there. A path that cannot be written is
// refused like bad input (status 2, one message) instead of failing in the collective
// HDF5 create on every rank (status 1 through MPI_Abort, and no reason given).
Decision check_writable(const fs::path& out, Decision d)
{
    const auto refuse = [&](const std::string& why) {
        return Decision{Mode::refuse, "cannot write the result " + out.string() + ": " + why +
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

void print_summary(const Job& job, const fs::path& out, const Progress& progress,
                   const std::vector<std::uint64_t>& histogram, bool complete, double peak_mib)
{
    const double s = progress.seconds();
    const auto n = progress.points_this_run();
    fmt::print(stderr, "{}: {} points computed in {:.2f} s ({:.3g} points/s), grid of {} points\n",
               complete ? "done" : "interrupted", n, s, s > 0 ? static_cast<double>(n) / s : 0.0, job.points());
    std::string line = "outcomes this run:";
    for (int o = 0; o < outcome_count; ++o) {
        const double frac = n ? static_cast<double>(histogram[static_cast<std::size_t>(o)]) / static_cast<double>(n) : 0.0;
        line += fmt::format("  {} {} ({:.2f}%)", name(static_cast<Outcome>(o)), histogram[static_cast<std::size_t>(o)],
                            100.0 * frac);
    }
    fmt::print(stderr, "{}\n", line);
    fmt::print(stderr, "peak memory per rank: {:.1f} MiB (largest rank)\n", peak_mib);
    fmt::print(stderr, "result: {}\n", out.string());
}

// What --dry-run prints: the validated job, one `key: value` a line, for people and scripts.
void print_plan(const Job& job, const fs::path& out, int ranks)
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
    fmt::print("model: e_wall {} alpha_wall {} e_floor {} alpha_floor {}\n", job.model.wall.e, job.model.wall.alpha,
               job.model.floor.e, job.model.floor.alpha);
    fmt::print("points: {}\nmax_bounces: {}\n", job.points(), job.max_bounces);
    if (job.refine != 0) fmt::print("refine: coarse stride {}\n", job.refine);
    if (Grid(job).on_boundary_plane()) fmt::print("boundary plane: xi = {} (limits from inside)\n", *job.grid[0].fixed);
    const Tiling tiling = default_tiling(job, ranks);
    fmt::print("tiles: {} of up to {} points for {} rank{}\n", tiling.tiles(), tiling.box(0).points(), ranks,
               ranks == 1 ? "" : "s");
    std::error_code ec;
    const bool exists = fs::exists(out, ec);
    fmt::print("output: {}\noutput exists: {}\n", out.string(), exists ? "yes" : "no");
    if (!exists) return;
    // For batch scripts deciding between a new run and --resume.
    try {
        const ResultInfo info = read_result_info(out);
        fmt::print("output complete: {} ({} of {} tiles done)\noutput same job: {}\n", info.complete ? "yes" : "no",
                   info.tiles_done, info.tiles, info.job_fingerprint == fingerprint(job) ? "yes" : "no");
    } catch (const std::exception&) {
        fmt::print("output complete: unreadable (not a superball result)\n");
    }
}

int explore(const ExploreOptions& opt)
{
    const auto started = std::chrono::steady_clock::now();
    // Before MPI starts: a signal during start-up then stops the run cleanly too.
    const StopSignals signals;
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    const bool root = world.is_root();
    h5::silence_errors();
    try {
        const Job job = load_job(opt.job);
        const fs::path out = opt.output.empty() ? fs::path(job.output) : fs::path(opt.output);
        if (out.empty()) throw InputError("no output file: set [run] output in " + opt.job + " or give --output");

        if (opt.dry_run) {
            if (root) print_plan(job, out, world.size());
            return 0;
        }

        Decision d;
        if (root) {
            d = decide(opt, out, job);
            if (d.mode == Mode::fresh) d = check_writable(out, std::move(d));
        }
        d.mode = static_cast<Mode>(world.broadcast(static_cast<std::int64_t>(d.mode)));
        world.broadcast(d.message);
        if (d.mode == Mode::refuse) throw InputError(d.message);
        if (root && !d.message.empty() && !opt.quiet) fmt::print(stderr, "{}\n", d.message);
        if (d.mode == Mode::complete) return 0;

        const Grid grid(job);
        ResultFile file = d.mode == Mode::fresh ? ResultFile::create(out, world, job, grid, default_tiling(job, world.size()))
                                                : ResultFile::open(out, world);
        const Tiling& tiling = file.tiling();

        std::deque<std::uint64_t> pending;
        std::uint64_t done_tiles = 0, done_points = 0;
        if (root) {
            const std::vector<std::uint8_t> done = file.tiles_done();
            for (std::uint64_t t = 0; t < done.size(); ++t) {
                if (done[t]) {
                    ++done_tiles;
                    done_points += tiling.box(t).points();
                } else {
                    pending.push_back(t);
                }
            }
            if (!opt.quiet) {
                fmt::print(stderr, "superball explore: {} points ({} tiles of up to {} points) on {} rank{}\n",
                           job.points(), tiling.tiles(), tiling.box(0).points(), world.size(),
                           world.size() == 1 ? "" : "s");
            }
        }
        Progress progress(stderr, opt.quiet, tiling.tiles(), tiling.points(), done_tiles, done_points);

        Starts starts;
        std::vector<std::uint32_t> counts;
        std::vector<std::uint8_t> outcomes;
        std::vector<std::uint64_t> histogram(outcome_count, 0);
        std::uint64_t computed = 0;  // points counted by the kernel (fewer than the tiles' with refinement)
        const CountKernel kernel = grid.on_boundary_plane() ? &count_each_on_plane
                                   : opt.kernel == "scalar"    ? &count_each
                                                               : &count_each_simd;
        TileCounter counter(kernel, job.max_bounces);
        std::vector<ModelRun> runs;
        const TileWork work = [&](std::uint64_t t, const Serve& serve) {
            const Box box = tiling.box(t);
            grid.starts(box, starts);
            grid.model_runs(box, runs);
            counts.resize(starts.size());
            outcomes.resize(starts.size());
            if (job.refine != 0) {
                const CountPoints some = [&](std::span<const std::uint64_t> points) {
                    counter.some(points, starts, runs, counts, outcomes, serve);
                };
                computed += refine_tile(box.count, job.refine, some, counts, outcomes);
            } else {
                counter.all(starts, runs, counts, outcomes, serve);
                computed += starts.size();
            }
            file.write_tile(t, counts, outcomes);
            for (const std::uint8_t o : outcomes) ++histogram[o];
        };
        const TileDone on_done = [&](std::uint64_t t, int) {
            progress.tile_done(tiling.box(t).points());
        };
        const ScheduleResult r = run_schedule(world, std::move(pending), work, on_done, &StopSignals::requested);

        if (root) progress.finish();
        // Attributes are written collectively and must be identical on every rank.
        const double run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        file.finish(world.broadcast(run_seconds), world.size(), !r.interrupted);
        histogram.push_back(computed);  // summed with the histogram: one reduction
        std::vector<std::uint64_t> total = world.sum(histogram);
        const std::uint64_t computed_total = total.back();
        total.pop_back();
        const double peak_mib = world.max(peak_rss_mib());
        if (root) {
            write_xdmf(out, read_result_info(out));
            print_summary(job, out, progress, total, !r.interrupted, peak_mib);
            if (job.refine != 0) {
                fmt::print(stderr, "refinement: {} of {} points counted ({:.1f}%), the others filled from agreeing corners\n",
                           computed_total, progress.points_this_run(),
                           100.0 * static_cast<double>(computed_total) / static_cast<double>(std::max<std::uint64_t>(progress.points_this_run(), 1)));
            }
            if (r.interrupted) {
                fmt::print(stderr, "stopped by a signal: {} is consistent and incomplete; run the same command with "
                                   "--resume to finish it\n",
                           out.string());
            }
        }
        return r.interrupted ? 1 : 0;
    } catch (const InputError& e) {
        // Every rank reads the same job and gets the same verdict: one message is enough.
        if (root) fmt::print(stderr, "superball explore: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        // Past the job's validation the ranks may no longer be in step: end them all.
        fmt::print(stderr, "superball explore (rank {}): error: {}\n", world.rank(), e.what());
        world.abort(1);
    }
}

}  // namespace

Runner add_explore_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("explore", "Count wall bounces over a grid of starts (run under mpirun)");
    sub->footer(
        "Run as `mpirun -n P superball explore JOB.toml` (P >= 1; every rank computes). The result is one HDF5\n"
        "file (SPEC.md section 5) plus a .xmf sidecar for ParaView. An existing result is never overwritten\n"
        "unless --overwrite is given; --resume finishes an interrupted run of the same job (a different job\n"
        "is refused). SIGINT/SIGTERM (or SIGUSR1/2, which mpirun forwards to every rank) stop cleanly\n"
        "(resumable); a second signal stops at once (still resumable).");
    auto opt = std::make_shared<ExploreOptions>();
    sub->add_option("job", opt->job, "TOML job file (SPEC.md section 4)")->required();
    sub->add_option("-o,--output", opt->output, "result file (default: [run] output of the job)");
    sub->add_flag("--resume", opt->resume, "finish an interrupted run of the same job in the output file");
    auto* overwrite = sub->add_flag("--overwrite", opt->overwrite, "replace an existing output file");
    sub->get_option("--resume")->excludes(overwrite);
    sub->add_flag("-q,--quiet", opt->quiet, "no progress lines");
    sub->add_option("--kernel", opt->kernel, "counting kernel: simd (vectorised) or scalar; identical results")
        ->check(CLI::IsMember({"simd", "scalar"}))
        ->capture_default_str();
    sub->add_flag("--dry-run", opt->dry_run, "check the job and print the plan (grid, tiles, output) without running");
    return [opt] { return explore(*opt); };
}

}  // namespace superball::cli
