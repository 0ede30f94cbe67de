#include "continuation_output.hpp"

#include <fmt/core.h>

#include <array>
#include <complex>
#include <string>
#include <vector>

namespace superball::cli {

namespace {

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& s)
{
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
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

}  // namespace

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

// Doubles as the shortest text that reads back to the same value (fmt's "{}").
void write_branches_csv(std::FILE* f, const ContinuationResult& result, const ContinuationRun& run, const Provenance& prov)
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


}  // namespace superball::cli
