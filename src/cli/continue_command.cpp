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

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& s)
{
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

std::string model_text(const Model& m)
{
    return fmt::format("e_wall {} alpha_wall {} e_floor {} alpha_floor {}", m.wall.e, m.wall.alpha, m.floor.e,
                       m.floor.alpha);
}

std::string start_text(const Cycle& c)
{
    const auto& p = c.points.front();
    return fmt::format("period {}{} cycle at (xi, U, W) = ({}, {}, {}), {}", c.period, c.corner ? " corner" : "", p.xi,
                       p.U, p.W, name(c.stability));
}

std::string eigenvalue_fields(const std::array<std::complex<double>, 3>& ev)
{
    return fmt::format("{},{},{},{},{},{}", ev[0].real(), ev[0].imag(), ev[1].real(), ev[1].imag(), ev[2].real(),
                       ev[2].imag());
}

// Doubles as the shortest text that reads back to the same value (fmt's "{}").
void write_csv(std::FILE* f, const ContinuationResult& result, const ContinuationRun& run, const Provenance& prov)
{
    const auto ranks = prov.mpi_ranks;
    const std::vector<ContinuedBranch>& branches = result.branches;
    const std::string p = std::string(name(run.parameter));
    fmt::print(f, "# superball continue: {} from {} to {}; model at the start: {}\n", p, run.settings.min,
               run.settings.max, model_text(run.model));
    fmt::print(f, "# {} branch{} on {} rank{}; steps {} (initial) to {} in arclength of (xi, U, W, {})\n",
               branches.size(), branches.size() == 1 ? "" : "es", ranks, ranks == 1 ? "" : "s", run.settings.initial_step,
               run.settings.max_step, p);
    for (std::size_t i = 0; i < branches.size(); ++i) {
        const ContinuedBranch& b = branches[i];
        fmt::print(f, "# branch {}: {}{}\n", i, start_text(b.start),
                   b.same_as ? fmt::format(": on branch {}, not repeated", *b.same_as)
                             : (b.branch ? fmt::format(", {} points", b.branch->points.size())
                                         : std::string(": not a regular point of the branch, not continued")));
    }
    fmt::print(f, "# (xi, U, W): the cycle's point with the smallest xi; lambda: product of the multipliers over the\n"
                  "# cycle; ev1..3: eigenvalues of the Jacobian of G^period by decreasing modulus; residual:\n"
                  "# max |G^period(s) - s| at the point followed; bracket: events, width of the final bracket in\n"
                  "# arclength (bounds the error in {})\n",
               p);
    fmt::print(f, "{}", provenance_comment(prov, "# "));
    fmt::print(f, "branch,period,corner,{},xi,U,W,lambda,ev1_re,ev1_im,ev2_re,ev2_im,ev3_re,ev3_im,stability,event,note,"
                  "residual,arclength,bracket\n",
               p);
    for (std::size_t i = 0; i < branches.size(); ++i) {
        if (!branches[i].branch) continue;
        const Branch& b = *branches[i].branch;
        for (const BranchPoint& q : b.points) {
            fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", i, b.period, b.domain == Domain::corner ? 1 : 0,
                       q.parameter, q.representative.xi, q.representative.U, q.representative.W, q.lambda,
                       eigenvalue_fields(q.eigenvalues), name(q.stability), name(q.event), csv_field(q.note), q.residual,
                       q.arclength, q.bracket);
        }
    }
}

std::string curve_text(const ContinuedCurve& c, const ContinuationResult& result, const ContinuationRun& run)
{
    const Branch& b = *result.branches[c.branch].branch;
    const BranchPoint& e = b.points[c.event];
    const std::string from = fmt::format("{} of branch {} (period {}{}) at {} = {}", name(e.event), c.branch, b.period,
                                         b.domain == Domain::corner ? " corner" : "", name(run.parameter), e.parameter);
    if (!c.curve) return from + ": no curve found";
    return fmt::format("{}: {} points; ends: {}; {}", from, c.curve->points.size(), c.curve->first_end,
                       c.curve->last_end);
}

// With --curve: the event curves in the plane of the two coefficients.
void write_curves_csv(std::FILE* f, const ContinuationResult& result, const ContinuationRun& run, const Provenance& prov)
{
    const auto ranks = prov.mpi_ranks;
    const std::string p = std::string(name(run.parameter));
    const std::string q = std::string(name(run.curves->second));
    const EventCurveSettings& set = run.curves->settings;
    fmt::print(f, "# superball continue: event curves in ({}, {}), {} from {} to {}, {} from {} to {}; model at the start: {}\n",
               p, q, p, set.min1, set.max1, q, set.min2, set.max2, model_text(run.model));
    fmt::print(f, "# {} branch{}, {} event curve{} on {} rank{}; steps {} (initial) to {} in the plane\n",
               result.branches.size(), result.branches.size() == 1 ? "" : "es", result.curves.size(),
               result.curves.size() == 1 ? "" : "s", ranks, ranks == 1 ? "" : "s", set.initial_step, set.max_step);
    for (std::size_t i = 0; i < result.curves.size(); ++i) {
        fmt::print(f, "# curve {}: {}\n", i, curve_text(result.curves[i], result, run));
    }
    fmt::print(f, "# each point: an event located on a line across the curve; (xi, U, W), lambda, ev1..3 and stability\n"
                  "# of the cycle there as in the branches' output\n");
    fmt::print(f, "{}", provenance_comment(prov, "# "));
    fmt::print(f, "curve,branch,event,period,corner,{},{},xi,U,W,lambda,ev1_re,ev1_im,ev2_re,ev2_im,ev3_re,ev3_im,"
                  "stability,note\n",
               p, q);
    for (std::size_t i = 0; i < result.curves.size(); ++i) {
        const ContinuedCurve& c = result.curves[i];
        if (!c.curve) continue;
        for (const EventCurvePoint& pt : c.curve->points) {
            const BranchPoint& b = pt.point;
            fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", i, c.branch, name(c.curve->event),
                       c.curve->period, c.curve->domain == Domain::corner ? 1 : 0, pt.first, pt.second,
                       b.representative.xi, b.representative.U, b.representative.W, b.lambda,
                       eigenvalue_fields(b.eigenvalues), name(b.stability), csv_field(b.note));
        }
    }
}

void write_json(std::FILE* f, const ContinuationResult& result, const ContinuationRun& run, int ranks)
{
    const std::vector<ContinuedBranch>& branches = result.branches;
    const std::string p = std::string(name(run.parameter));
    const Model& m = run.model;
    fmt::print(f, "{{\n  \"model\": {{\"e_wall\": {}, \"alpha_wall\": {}, \"e_floor\": {}, \"alpha_floor\": {}}},\n",
               m.wall.e, m.wall.alpha, m.floor.e, m.floor.alpha);
    fmt::print(f, "  \"parameter\": \"{}\", \"min\": {}, \"max\": {}, \"ranks\": {},\n", p, run.settings.min,
               run.settings.max, ranks);
    fmt::print(f, "  \"step\": {}, \"min_step\": {}, \"max_step\": {}, \"max_points\": {},\n", run.settings.initial_step,
               run.settings.min_step, run.settings.max_step, run.settings.max_points);
    if (run.start) {
        fmt::print(f, "  \"start\": {{\"xi\": {}, \"U\": {}, \"W\": {}, \"period\": {}}},\n", run.start->xi, run.start->U,
                   run.start->W, run.period);
    } else {
        fmt::print(f, "  \"search\": {{\"max_period\": {}, \"starts\": {}, \"seed\": {}, \"corner\": {}}},\n",
                   run.search.max_period, run.search.starts, run.search.seed, run.search.corner);
    }
    fmt::print(f, "  \"branches\": [");
    const char* sep = "\n";
    for (std::size_t i = 0; i < branches.size(); ++i) {
        const ContinuedBranch& cb = branches[i];
        const Cycle& c = cb.start;
        const auto& s = c.points.front();
        fmt::print(f, "{}    {{\"branch\": {}, \"period\": {}, \"corner\": {},\n", sep, i, c.period, c.corner);
        fmt::print(f, "     \"start_cycle\": {{\"xi\": {}, \"U\": {}, \"W\": {}, \"lambda\": {}, \"stability\": \"{}\"}},\n",
                   s.xi, s.U, s.W, c.lambda, name(c.stability));
        if (cb.same_as) {
            fmt::print(f, "     \"same_as\": {}, \"points\": []}}", *cb.same_as);
        } else if (!cb.branch) {
            fmt::print(f, "     \"same_as\": null, \"continued\": false, \"points\": []}}");
        } else {
            const Branch& b = *cb.branch;
            fmt::print(f, "     \"same_as\": null, \"continued\": true, \"start_index\": {}, \"points\": [", b.start);
            const char* psep = "\n";
            for (const BranchPoint& q : b.points) {
                fmt::print(f, "{}      {{\"{}\": {}, \"xi\": {}, \"U\": {}, \"W\": {}, \"lambda\": {}, \"eigenvalues\": [", psep, p,
                           q.parameter, q.representative.xi, q.representative.U, q.representative.W, q.lambda);
                for (std::size_t k = 0; k < q.eigenvalues.size(); ++k) {
                    fmt::print(f, "{}{{\"re\": {}, \"im\": {}}}", k ? ", " : "", q.eigenvalues[k].real(),
                               q.eigenvalues[k].imag());
                }
                fmt::print(f, "], \"stability\": \"{}\", \"event\": \"{}\", \"note\": {},\n", name(q.stability), name(q.event),
                           quote(q.note));
                fmt::print(f, "       \"point\": {{\"xi\": {}, \"U\": {}, \"W\": {}}}, \"residual\": {}, \"arclength\": {}, "
                              "\"bracket\": {}}}",
                           q.point.xi, q.point.U, q.point.W, q.residual, q.arclength, q.bracket);
                psep = ",\n";
            }
            fmt::print(f, "\n     ]}}");
        }
        sep = ",\n";
    }
    fmt::print(f, "\n  ]");
    if (run.curves) {
        const std::string q = std::string(name(run.curves->second));
        const EventCurveSettings& set = run.curves->settings;
        fmt::print(f, ",\n  \"curve_parameter\": \"{}\", \"curve_min\": {}, \"curve_max\": {}, \"curves\": [", q, set.min2,
                   set.max2);
        sep = "\n";
        for (std::size_t i = 0; i < result.curves.size(); ++i) {
            const ContinuedCurve& c = result.curves[i];
            fmt::print(f, "{}    {{\"curve\": {}, \"branch\": {}, \"event_index\": {}, \"text\": {}", sep, i, c.branch, c.event,
                       quote(curve_text(c, result, run)));
            if (!c.curve) {
                fmt::print(f, ", \"points\": []}}");
            } else {
                fmt::print(f, ", \"event\": \"{}\", \"start_index\": {}, \"ends\": [{}, {}], \"points\": [",
                           name(c.curve->event), c.curve->start, quote(c.curve->first_end), quote(c.curve->last_end));
                const char* psep = "\n";
                for (const EventCurvePoint& pt : c.curve->points) {
                    const BranchPoint& b = pt.point;
                    fmt::print(f, "{}      {{\"{}\": {}, \"{}\": {}, \"xi\": {}, \"U\": {}, \"W\": {}, \"lambda\": {}, "
                                  "\"eigenvalues\": [",
                               psep, name(run.parameter), pt.first, q, pt.second, b.representative.xi, b.representative.U,
                               b.representative.W, b.lambda);
                    for (std::size_t k = 0; k < b.eigenvalues.size(); ++k) {
                        fmt::print(f, "{}{{\"re\": {}, \"im\": {}}}", k ? ", " : "", b.eigenvalues[k].real(),
                                   b.eigenvalues[k].imag());
                    }
                    fmt::print(f, "], \"stability\": \"{}\", \"note\": {}, \"point\": {{\"xi\": {}, \"U\": {}, \"W\": {}}}, "
                                  "\"residual\": {}, \"bracket\": {}}}",
                               name(b.stability), quote(b.note), b.point.xi, b.point.U, b.point.W, b.residual, b.bracket);
                    psep = ",\n";
                }
                fmt::print(f, "\n     ]}}");
            }
            sep = ",\n";
        }
        fmt::print(f, "\n  ]");
    }
    fmt::print(f, "\n}}\n");
}

int run(const ContinueOptions& opt)
{
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    // For the CSV header: the run as it starts (collective: every rank counts the hosts).
    const Provenance prov{process_command_line(), utc_now(), world.size(), mpi::host_count(world), 1, ""};
    ContinuationRun cont;
    ContinuationResult result;
    try {
        cont = resolve(opt);
        result = continue_branches(cont, world);
    } catch (const InputError& e) {
        // Every rank checks the same input and gets the same verdict: one message is enough.
        if (world.is_root()) fmt::print(stderr, "superball continue: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        // The other ranks would wait in a collective for ever: end them all.
        fmt::print(stderr, "superball continue (rank {}): error: {}\n", world.rank(), e.what());
        world.abort(1);
    }
    if (!world.is_root()) return 0;

    write_output(opt.output, [&](std::FILE* f) {
        if (opt.format == "json") {
            write_json(f, result, cont, world.size());
        } else if (cont.curves) {
            write_curves_csv(f, result, cont, prov);
        } else {
            write_csv(f, result, cont, prov);
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
