// superball continue: branches of cycles of the canonical map followed in one coefficient
// (pseudo-arclength continuation), with their folds, bifurcations and ends.
#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "every_rank.hpp"
#include "continuation_output.hpp"
#include "core/continuation.hpp"
#include "mpi/mpi.hpp"
#include "options.hpp"
#include "run/continuation.hpp"
#include "core/event_curve.hpp"
#include "job/provenance.hpp"

namespace superball::cli {

namespace {

// The flags: those of the library's ContinuationInput, --start as text, the output's.
struct ContinueOptions {
    ContinuationInput in;
    std::string start;
    std::string format = "csv";
    std::string output;
};

// "xi,U,W" as three numbers (resolve_continuation checks they are a launch).
CanonicalState<double> parse_start(const std::string& text)
{
    std::vector<double> v;
    std::size_t from = 0;
    while (from <= text.size()) {
        const std::size_t comma = std::min(text.find(',', from), text.size());
        const std::string field = text.substr(from, comma - from);
        double x = 0.0;
        const auto r = std::from_chars(field.data(), field.data() + field.size(), x);
        if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size() || !std::isfinite(x)) {
            throw InputError("--start = " + text + " is not three numbers: accepted xi,U,W, e.g. 0.25,-0.56,-1.36");
        }
        v.push_back(x);
        from = comma + 1;
    }
    if (v.size() != 3) throw InputError("--start = " + text + " is not three numbers: accepted xi,U,W, e.g. 0.25,-0.56,-1.36");
    return {v[0], v[1], v[2]};
}

ContinuationRun resolve(const ContinueOptions& opt)
{
    ContinuationInput in = opt.in;
    if (!opt.start.empty()) in.start = parse_start(opt.start);
    ContinuationRun run = resolve_continuation(in, flag_spelling);
    if (opt.format != "csv" && opt.format != "json") {
        throw InputError("--format = " + opt.format + " is not a format: accepted csv or json");
    }
    return run;
}

int run(const ContinueOptions& opt)
{
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    // For the CSV header: the run as it starts (collective: every rank counts the hosts).
    const Provenance prov{process_command_line(), utc_now(), world.size(), mpi::host_count(world), 1, ""};
    ContinuationRun cont;
    ContinuationResult result;
    const int status = on_every_rank("continue", world, [&] {
        cont = resolve(opt);
        result = continue_branches(cont, world);
        return 0;
    });
    // The output after the ranks are done with each other: a file that cannot be written
    // ends rank 0 alone (main's error path).
    if (status != 0 || !world.is_root()) return status;

    write_output(opt.output, [&](std::FILE* f) {
        if (opt.format == "json") {
            fmt::print(f, "{}", continuation_json(result, cont, world.size()));
        } else if (cont.curves) {
            write_curves_csv(f, result, cont, prov);
        } else {
            write_branches_csv(f, result, cont, prov);
        }
    });
    return 0;
}

}  // namespace

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
    return [opt] { return run(*opt); };
}

}  // namespace superball::cli
