// superball: regions of initial conditions of a superball bouncing between a floor and a wall.
// The command line, all of it: every subcommand's options are declared here and parsed into
// its options struct (NAME_command.hpp), then the subcommand's function runs. This is the only
// file that includes CLI11: version 2.1 (Debian's) is header-only, and each file using it
// compiled its parser anew, 7 s at -O3 and 13 s under the sanitizers (measured on a file
// declaring four options), which made the command files the slowest part of the build.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analyse_command.hpp"
#include "continue_command.hpp"
#include "count_command.hpp"
#include "explore_command.hpp"
#include "fixed_points_command.hpp"
#include "info_command.hpp"
#include "options.hpp"
#include "serve_command.hpp"
#include "trajectory_command.hpp"
#include "core/input.hpp"
#include "core/kernels.hpp"
#include "job/spelling.hpp"
#include "run/continuation.hpp"
#include "superball/version.hpp"

namespace {

bool is_number(std::string_view arg)
{
    const std::string text(arg);
    char* end = nullptr;
    std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size();
}

// CLI11 reports an unknown flag as "arguments were not expected: VALUE --FLAG", values
// and flags mixed. Name the first argument that looks like a flag yet is none of
// `command`'s (or the top level's), and the flag it most likely meant.
std::optional<std::string> unknown_flag_message(const CLI::App& app, const CLI::App& command, int argc, char** argv)
{
    std::vector<std::string> known;
    for (const CLI::App* a : {&app, &command}) {
        for (const CLI::Option* o : a->get_options()) {
            for (const std::string& n : o->get_lnames()) known.push_back("--" + n);
            for (const std::string& n : o->get_snames()) known.push_back("-" + n);
        }
    }
    const auto is_known = [&](std::string_view name) {
        return std::find(known.begin(), known.end(), name) != known.end();
    };
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--") break;
        if (arg.size() < 2 || arg[0] != '-' || is_number(arg)) continue;
        const std::string_view name = arg.substr(0, arg.find('='));
        // -ofile: a short flag with its value attached.
        if (is_known(name) || (arg[1] != '-' && is_known(arg.substr(0, 2)))) continue;
        const auto near = superball::suggestion(name, known);
        return fmt::format("superball {}: unknown option {} ({})", command.get_name(), name,
                           near ? "did you mean " + *near + "?" : "see superball " + command.get_name() + " --help");
    }
    return std::nullopt;
}

}  // namespace

namespace superball::cli {

namespace {

// Runs the subcommand the command line chose; returns the process exit status.
using Runner = std::function<int()>;

// Options shared by several subcommands.
void add_model_flags(CLI::App& app, ModelInput& in)
{
    const std::string e_help = std::string("normal coefficient of restitution, ") + e_range_text;
    const std::string a_help = std::string("tangential coefficient of restitution, ") + alpha_range_text +
                               " (-1 smooth, 1 perfectly rough)";
    app.add_option("--e", in.e, e_help + ", both surfaces")->group("Model");
    app.add_option("--alpha", in.alpha, a_help + ", both surfaces")->group("Model");
    app.add_option("--e-wall", in.e_wall, "wall's e (overrides --e)")->group("Model");
    app.add_option("--alpha-wall", in.alpha_wall, "wall's alpha (overrides --alpha)")->group("Model");
    app.add_option("--e-floor", in.e_floor, "floor's e (overrides --e)")->group("Model");
    app.add_option("--alpha-floor", in.alpha_floor, "floor's alpha (overrides --alpha)")->group("Model");
    // SPEC.md 1b: Walton's friction law and the ball's moment of inertia.
    app.add_option("--mu", in.mu,
                   std::string("Coulomb friction coefficient, ") + mu_range_text + "; default inf, both surfaces")
        ->group("Model");
    app.add_option("--mu-wall", in.mu_wall, "wall's mu (overrides --mu)")->group("Model");
    app.add_option("--mu-floor", in.mu_floor, "floor's mu (overrides --mu)")->group("Model");
    app.add_option("--inertia", in.inertia,
                   std::string("the ball's moment of inertia over m a^2, ") + inertia_range_text +
                       "; default 0.4, a solid ball")
        ->group("Model");
}

void add_start_flags(CLI::App& app, StartInput& in)
{
    const char* canonical = "Canonical start";
    app.add_option("--xi", in.xi, "g x / (2 |u| v): launch distance as a fraction of the free-flight range, > 0")
        ->group(canonical);
    app.add_option("--U", in.U, "u / v: launch direction, < 0")->group(canonical);
    app.add_option("--W", in.W, "a omega / v: spin relative to the vertical speed")->group(canonical);
    const char* physical = "Physical start";
    app.add_option("--x", in.x, "distance of the centre from the wall [m], > 0")->group(physical);
    app.add_option("--u", in.u, "horizontal velocity [m/s], < 0 (toward the wall)")->group(physical);
    app.add_option("--v", in.v, "vertical velocity [m/s], > 0")->group(physical);
    app.add_option("--omega", in.omega, "spin [rad/s], counter-clockwise positive")->group(physical);
    app.add_option("--g", in.g, "gravity [m/s^2] (default 9.81)")->group(physical);
    app.add_option("--radius", in.radius, "ball radius a [m] (default 0.025)")->group(physical);
}

// Taken as text and checked by the library (resolve_max_bounces), as Python's count is, so
// that both refuse a bad limit in the same words.
void add_max_bounces_flag(CLI::App& app, std::string& max_bounces)
{
    app.add_option("--max-bounces", max_bounces, "stop after this many wall impacts (outcome capped), 1 to 4294967295")
        ->type_name("INT")
        ->capture_default_str();
}

// The flags of the commands that follow one start point (count, trajectory).
void add_one_start_flags(CLI::App& app, ModelInput& model, StartInput& start, std::string& max_bounces)
{
    add_model_flags(app, model);
    add_start_flags(app, start);
    add_max_bounces_flag(app, max_bounces);
}

// One function per subcommand: its options, and the function that runs it.
Runner add_count_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("count", "Count the wall bounces of one start point");
    sub->footer(
        "Example: superball count --xi 0.05 --U -1 --W -2 --e 0.9 --alpha 0.9\n"
        "Prints the number of wall impacts and the outcome: left (the ball moved away from the wall),\n"
        "missed (it landed on the floor before reaching the wall), capped (--max-bounces reached),\n"
        "invalid (not a launch toward the wall).");
    auto opt = std::make_shared<CountOptions>();
    add_one_start_flags(*sub, opt->model, opt->start, opt->max_bounces);
    sub->add_flag("--json", opt->json, "print a JSON object instead of a sentence");
    return [opt] { return count_command(*opt); };
}

Runner add_trajectory_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("trajectory", "Print every impact of one start point (CSV or JSON)");
    sub->footer(
        "Events: launch, wall (impact), floor (bounce), land (the floor contact after the motion ended,\n"
        "recorded, not applied). Columns: time t, centre (x, y), velocities and spin arriving (_in) and\n"
        "leaving. A canonical start is followed in dimensionless units (v0 = g = radius = 1, so omega = W);\n"
        "a physical start in SI units. --samples K adds K points on every flight (event 'path') for plotting.");
    auto opt = std::make_shared<TrajectoryOptions>();
    add_one_start_flags(*sub, opt->model, opt->start, opt->max_bounces);
    sub->add_option("--format", opt->format, "csv or json")->check(CLI::IsMember({"csv", "json"}))->capture_default_str();
    sub->add_option("--samples", opt->samples, "points sampled on each flight parabola (0: none, otherwise >= 2)")
        ->check(CLI::Range(0, 100000));
    sub->add_option("-o,--output", opt->output, "write to this file instead of standard output");
    return [opt] { return trajectory_command(*opt); };
}

Runner add_explore_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("explore", "Count wall bounces over a grid of starts (run under mpirun)");
    sub->footer(
        "Run as `mpirun -n P superball explore JOB.toml` (P >= 1). The result is one HDF5 file in\n"
        "netCDF-4/CF layout (xarray, ncdump, h5py read it), compressed, plus a .xmf sidecar for ParaView.\n"
        "While the run goes on, its tiles are in OUTPUT.partial; the result takes its name only once\n"
        "complete. An existing result is never overwritten unless --overwrite is given, and only a\n"
        "superball file is ever replaced; --resume finishes an interrupted run of the same job (a different\n"
        "job is refused). SIGINT/SIGTERM (or SIGUSR1/2, which mpirun forwards to every rank) stop cleanly\n"
        "(resumable); a second signal stops at once (still resumable).");
    auto opt = std::make_shared<ExploreOptions>();
    sub->add_option("job", opt->job, "TOML job file (SPEC.md section 4)")->required();
    sub->add_option("-o,--output", opt->output, "result file (default: [run] output of the job)");
    sub->add_flag("--resume", opt->resume, "finish an interrupted run of the same job in the output file");
    auto* overwrite = sub->add_flag("--overwrite", opt->overwrite, "replace an existing output file");
    sub->get_option("--resume")->excludes(overwrite);
    sub->add_flag("-q,--quiet", opt->quiet, "no progress lines");
    sub->add_option("--stop-after", opt->stop_after,
                    "stop cleanly after this many seconds, as on SIGTERM (resumable with --resume): a time budget for "
                    "batch jobs")
        ->check(CLI::NonNegativeNumber);
    std::string variants;
    for (const KernelVariant& k : simd_kernels()) variants += (variants.empty() ? "" : ", ") + std::string(k.name);
    sub->add_option("--kernel", opt->kernel,
                    "counting kernel, identical results: simd (the widest variant this processor runs, here " +
                        describe(best_kernel()) + "), scalar, or a variant of this build (" + variants +
                        "); default: $SUPERBALL_KERNEL, else simd");
    sub->add_flag("--stats", opt->stats,
                  "after the run, print how the schedule went: tiles per rank (fewest, most), blocks rank 0 handed "
                  "out, messages it received, tiles given back (the figures tests/scale/simulate.sh predicts)");
    sub->add_option("--node-ranks", opt->node_ranks,
                    "schedule as if every N consecutive ranks were a node (default: the ranks sharing memory): "
                    "the cluster's two-level schedule on one machine, for tests")
        ->check(CLI::Range(1, std::numeric_limits<int>::max()));
    sub->add_option("--writers", opt->writers,
                    "processes that write the compressed result: a count (rank 0 and node leaders, at most one per "
                    "node, spread evenly; each writes its share of the nodes' tiles into stripes of [run] alignment "
                    "that rank 0 grants it) or auto (one per node from 64 ranks on, else rank 0 alone); default: "
                    "the job's [run] writers, else auto");
    sub->add_flag("--dry-run", opt->dry_run, "check the job and print the plan (grid, tiles, output) without running");
    return [opt] { return explore_command(*opt); };
}

Runner add_info_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("info", "Describe a result file: job, shape, completeness, outcomes");
    sub->footer("FILE is a result (OUTPUT of a job) or the partial file of an interrupted run (OUTPUT.partial);\n"
                "given a result's name whose run has not finished, info describes its partial file. Every object\n"
                "and value is checked: a damaged file is reported (exit status 2), never half-read.");
    auto opt = std::make_shared<InfoOptions>();
    sub->add_option("file", opt->file, "result file (.h5) written by superball explore, or its .partial file")->required();
    return [opt] { return info_command(*opt); };
}

Runner add_analyse_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("analyse", "Structure of the regions of a 2-D result: areas, boundaries, fractal dimension, "
                                              "basin entropy");
    sub->footer(
        "The class of a point is its wall-bounce count (with --with-outcome: count and outcome);\n"
        "points with outcome invalid belong to no class. Reports area fractions, the length of\n"
        "the boundaries between classes, the uncertainty exponent alpha (the fraction of points with\n"
        "another class within e cells along their row or column ~ e^alpha) and D = 2 - alpha, the\n"
        "box-counting dimension of the boundary, and the basin entropy S_b, S_bb (Daza et al. 2016).\n"
        "The file is read a band of rows at a time: memory grows with the row length, not the grid.\n"
        "Example: superball analyse results/quickstart.h5 --json");
    auto opt = std::make_shared<AnalyseOptions>();
    sub->add_option("file", opt->file, "result file (.h5) written by superball explore")->required();
    sub->add_option("--slice", opt->slice, "the plane of a 3-D result: AXIS=INDEX, e.g. U=0 (required for 3-D results)");
    sub->add_option("--box", opt->box, "side of the basin-entropy boxes, in points")
        ->check(CLI::Range(std::size_t{1}, std::size_t{4096}))
        ->capture_default_str();
    sub->add_option("--eps-max", opt->eps_max,
                    "largest distance e (cells) for the uncertainty exponent; e = 1, 2, 4, ... up to it "
                    "(default: min(rows, cols)/64, at least 2)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--box-max", opt->box_max,
                    "largest box side s (cells) for box counting; s = 1, 2, 4, ... up to it (default: min(rows, cols)/16)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--top", opt->top, "pairs of classes listed by boundary length")->capture_default_str();
    sub->add_flag("--with-outcome", opt->with_outcome, "classes are (count, outcome) pairs, not counts alone");
    sub->add_flag("--json", opt->json, "print a JSON object instead of a report");
    return [opt] { return analyse_command(*opt); };
}

Runner add_fixed_points_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("fixed-points", "Fixed points and cycles of the canonical map (self-similar motions)");
    sub->footer(
        "Solves G^k(s) = s for k = 1..--period by damped Newton's method from --starts seeded starts in\n"
        "0 < xi < 1, U < 0, keeping the solutions whose whole cycle stays there (residual <= 1e-10).\n"
        "For each distinct cycle: its period, the point with the smallest xi, the product lambda of the\n"
        "multipliers (scale factor per period), the eigenvalues of the Jacobian of G^k and the stability\n"
        "(stable, unstable, saddle, marginal: some |eigenvalue| within 1e-9 of 1). Under mpirun the starts\n"
        "are shared among the ranks; the result does not depend on their number.\n"
        "--corner also looks for cycles on the corner plane xi = 0, where the wall sends the ball down\n"
        "and G maps the plane into itself: the limits of motions that go into the corner. Their\n"
        "eigenvalues include the transverse multiplier kappa = d xi'/d xi (< 1: nearby launches approach\n"
        "the corner, with infinitely many bounces).\n"
        "Example: superball fixed-points --e 0.9 --alpha 1 --period 3 --format json");
    auto opt = std::make_shared<FixedPointOptions>();
    add_model_flags(*sub, opt->model);
    sub->add_option("--period", opt->period, "largest period k to look for, 1..8")->capture_default_str();
    sub->add_option("--starts", opt->starts, "number of Newton starts, >= 1")->capture_default_str();
    sub->add_option("--seed", opt->seed, "seed of the random starts (std::mt19937_64)")->capture_default_str();
    sub->add_option("--format", opt->format, "table or json")->capture_default_str();
    sub->add_option("-o,--output", opt->output, "write to this file instead of standard output");
    sub->add_flag("--corner", opt->corner, "also look for cycles on the corner plane xi = 0");
    return [opt] { return fixed_points_command(*opt); };
}

Runner add_continue_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("continue", "Branches of cycles of the canonical map followed in one coefficient "
                                               "(bifurcation diagram)");
    sub->footer(
        "Pseudo-arclength continuation of the cycles of G (as found by fixed-points) in the coefficient\n"
        "--param, between --min and --max, from the model the model flags give: the branch is the curve\n"
        "G^k(x; p) = x in (xi, U, W, p), followed around folds where p turns back. Without --start every\n"
        "cycle the fixed-point search finds (periods 1..--period, --starts, --seed, --corner as in\n"
        "fixed-points) starts a branch; with --start xi,U,W the cycle of period --period that Newton's\n"
        "method finds from there (xi = 0: on the corner plane). Each branch is followed both ways.\n"
        "Events, located to 1e-10 in arclength (so in the parameter) where a test function changes sign:\n"
        "  fold             the parameter turns back (an eigenvalue of D(G^k) passes 1)\n"
        "  period_doubling  a real eigenvalue passes -1\n"
        "  neimark_sacker   a complex pair crosses the unit circle (note: its angle)\n"
        "  branch_point     an eigenvalue 1 without a fold: another branch crosses; on the corner plane\n"
        "                   also kappa = 1, where a branch of interior cycles meets the plane\n"
        "  boundary         a point of the cycle reaches xi = 0, xi = 1 or U = 0 (or, on the corner plane,\n"
        "                   the wall stops sending the ball down): the branch leaves the region, stops\n"
        "  end              --min or --max (solved there exactly), or the branch cannot go on (note says why)\n"
        "Output: one row per point (CSV with # comment lines, or JSON): branch, period, corner, the\n"
        "parameter, xi, U, W (the cycle's point with the smallest xi), lambda, ev1..3 (re, im),\n"
        "stability, event, note, residual, arclength, bracket. Under mpirun the branches are shared among\n"
        "the ranks; the output does not depend on their number.\n"
        "--curve Q (with --curve-min, --curve-max) then follows every fold, period doubling, Neimark-Sacker\n"
        "and branch point as a curve in the plane (--param, Q): each curve point is that event located on a\n"
        "line across the curve (secant predictor); the CSV then lists the curves' points instead (curve,\n"
        "branch, event, period, corner, the two coefficients, xi, U, W, lambda, ev1..3, stability, note);\n"
        "the JSON has both.\n"
        "Example: superball continue --e 0.9 --alpha 0.99 --param alpha --min 0.95 --max 1 --corner\n"
        "         | analysis/bifurcation_plot.py - -o alpha.png");
    auto opt = std::make_shared<ContinueOptions>();
    add_model_flags(*sub, opt->in.model);
    sub->add_option("--param", opt->in.param, "coefficient to continue in: " + parameter_list());
    sub->add_option("--min", opt->in.min, "lower bound of the parameter");
    sub->add_option("--max", opt->in.max, "upper bound of the parameter");
    sub->add_option("--start", opt->start, "xi,U,W near the cycle to continue (xi = 0: corner plane)");
    sub->add_option("--period", opt->in.period, "period k of the cycle(s), 1..8 (without --start: 1..k)")->capture_default_str();
    sub->add_option("--starts", opt->in.starts, "Newton starts of the fixed-point search, >= 1")->capture_default_str();
    sub->add_option("--seed", opt->in.seed, "seed of the search's starts")->capture_default_str();
    sub->add_flag("--corner", opt->in.corner, "the search also looks on the corner plane xi = 0");
    sub->add_option("--step", opt->in.step, "initial arclength step, 0 < step <= --max-step (default: 0.01 or --max-step)");
    sub->add_option("--max-step", opt->in.max_step, "largest arclength step, >= --step")->capture_default_str();
    sub->add_option("--min-step", opt->in.min_step, "smallest step before the branch is given up")->capture_default_str();
    sub->add_option("--max-points", opt->in.max_points, "points per direction of a branch, >= 1")->capture_default_str();
    sub->add_option("--format", opt->format, "csv or json")->capture_default_str();
    sub->add_option("-o,--output", opt->output, "write to this file instead of standard output");
    const char* curves = "Event curves (two-parameter continuation)";
    sub->add_option("--curve", opt->in.curve, "follow every event of the branches as a curve in (--param, this coefficient)")
        ->group(curves);
    sub->add_option("--curve-min", opt->in.curve_min, "lower bound of the --curve coefficient")->group(curves);
    sub->add_option("--curve-max", opt->in.curve_max, "upper bound of the --curve coefficient")->group(curves);
    sub->add_option("--curve-step", opt->in.curve_step, "initial step in the plane, > 1e-05")->capture_default_str()->group(curves);
    sub->add_option("--curve-max-step", opt->in.curve_max_step, "largest step in the plane")->capture_default_str()->group(curves);
    sub->add_option("--curve-max-points", opt->in.curve_max_points, "points per direction of a curve, >= 1")
        ->capture_default_str()
        ->group(curves);
    return [opt] { return continue_command(*opt); };
}

Runner add_serve_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("serve", "Explore the regions in a browser: an HTTP server with a deep-zoom map");
    sub->footer(
        "Serves a page with a deep-zoom map of wall-bounce counts (or outcomes) over two canonical axes, computed\n"
        "on demand at the zoom's resolution, the trajectory of a clicked launch, and \"export this view\" as a\n"
        "job file; and the JSON API behind it (/api/count, /api/region, /api/trajectory, /api/job; docs/commands.md).\n"
        "Result files given as arguments open as layers. Binds to 127.0.0.1 (this machine only) unless --host\n"
        "says otherwise; prints the URL and serves until Ctrl-C or SIGTERM.");
    auto opt = std::make_shared<ServeOptions>();
    serve::ServeSettings& s = opt->settings;
    sub->add_option("results", opt->layers, "result files (.h5, or a partial file) to show as layers")->check(CLI::ExistingFile);
    sub->add_option("--host", s.host, "address to listen on (0.0.0.0: every interface; anyone who reaches it can use it)")
        ->capture_default_str();
    sub->add_option("--port", s.port, "port (0: any free port)")->check(CLI::Range(0, 65535))->capture_default_str();
    sub->add_option("--threads", s.threads, "counting threads (default: one per core)")->check(CLI::Range(1u, 1024u));
    sub->add_option("--time-limit", s.time_limit, "seconds a request may compute before it is refused (HTTP 503)")
        ->check(CLI::Range(0.001, 86400.0))
        ->capture_default_str();
    return [opt] { return serve_command(*opt); };
}

}  // namespace

}  // namespace superball::cli

int main(int argc, char** argv)
{
    using namespace superball;
    CLI::App app{"superball: how many times a spinning superball bounces between a floor and a wall\n"
                 "(Cross impact model) before it escapes, for one start or a whole grid of starts.",
                 "superball"};
    // The kernel line names the instruction set a run here would count with (SUPERBALL_KERNEL
    // included), for bug reports and for checking a node's binary.
    app.set_version_flag("--version", [] { return std::string("superball ") + software_version + "\n" + kernel_report(); });
    app.require_subcommand(1);
    app.footer("Run `superball COMMAND --help` for the options of a command. Exit status: 0 success,\n"
               "2 bad input (the message names it), 1 other failure.");

    std::map<const CLI::App*, cli::Runner> runners;
    for (auto add : {cli::add_explore_command, cli::add_count_command, cli::add_trajectory_command,
                     cli::add_info_command, cli::add_analyse_command, cli::add_fixed_points_command,
                     cli::add_continue_command, cli::add_serve_command}) {
        auto run = add(app);
        runners.emplace(app.get_subcommands({}).back(), std::move(run));
    }

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        const auto chosen = app.get_subcommands();
        if (argc > 1 && argv[1][0] != '-' && chosen.empty()) {
            // CLI11 says "a subcommand is required" for a misspelt command: name it instead.
            std::vector<std::string> commands;
            for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
            const auto near = suggestion(argv[1], commands);
            fmt::print(stderr, "superball: unknown command '{}' ({})\n", argv[1],
                       near ? "did you mean " + *near + "?" : fmt::format("commands: {}; see --help", fmt::join(commands, ", ")));
            return 2;
        }
        const auto unknown = dynamic_cast<const CLI::ExtrasError*>(&e) == nullptr || chosen.empty()
                                 ? std::nullopt
                                 : unknown_flag_message(app, *chosen.front(), argc, argv);
        if (unknown) {
            fmt::print(stderr, "{}\n", *unknown);
        } else {
            fmt::print(stderr, "superball: {} (run with --help for usage)\n", e.what());
        }
        return 2;
    }
    const CLI::App* chosen = app.get_subcommands().front();
    try {
        return runners.at(chosen)();
    } catch (const InputError& e) {
        fmt::print(stderr, "superball {}: {}\n", chosen->get_name(), e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "superball {}: error: {}\n", chosen->get_name(), e.what());
        return 1;
    }
}
