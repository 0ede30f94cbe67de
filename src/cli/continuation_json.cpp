#include <array>
#include <complex>
#include <nlohmann/json.hpp>
#include <string>

#include "continuation_output.hpp"
#include "job/result_json.hpp"

namespace superball::cli {

namespace {

nlohmann::ordered_json eigenvalues_json(const std::array<std::complex<double>, 3>& ev)
{
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const std::complex<double>& z : ev) out.push_back({{"re", z.real()}, {"im", z.imag()}});
    return out;
}

nlohmann::ordered_json xi_u_w(const CanonicalState<double>& s) { return {{"xi", s.xi}, {"U", s.U}, {"W", s.W}}; }

nlohmann::ordered_json branch_json(std::size_t i, const ContinuedBranch& cb, const std::string& p)
{
    const Cycle& c = cb.start;
    const auto& s = c.points.front();
    nlohmann::ordered_json out = {{"branch", i}, {"period", c.period}, {"corner", c.corner}};
    out["start_cycle"] = {{"xi", s.xi}, {"U", s.U}, {"W", s.W}, {"lambda", c.lambda}, {"stability", name(c.stability)}};
    out["same_as"] = cb.same_as ? nlohmann::ordered_json(*cb.same_as) : nlohmann::ordered_json(nullptr);
    if (!cb.same_as) out["continued"] = cb.branch.has_value();
    if (cb.branch) out["start_index"] = cb.branch->start;
    out["points"] = nlohmann::ordered_json::array();
    if (cb.same_as || !cb.branch) return out;
    for (const BranchPoint& q : cb.branch->points) {
        nlohmann::ordered_json pt = {{p, q.parameter}, {"xi", q.representative.xi}, {"U", q.representative.U},
                                     {"W", q.representative.W}, {"lambda", q.lambda}};
        pt["eigenvalues"] = eigenvalues_json(q.eigenvalues);
        pt.update({{"stability", name(q.stability)}, {"event", name(q.event)}, {"note", q.note}, {"point", xi_u_w(q.point)},
                   {"residual", q.residual}, {"arclength", q.arclength}, {"bracket", q.bracket}});
        out["points"].push_back(std::move(pt));
    }
    return out;
}

nlohmann::ordered_json curve_json(std::size_t i, const ContinuedCurve& c, const ContinuationResult& result,
                                  const ContinuationRun& run)
{
    const std::string p(name(run.parameter));
    const std::string q(name(run.curves->second));
    nlohmann::ordered_json out = {{"curve", i}, {"branch", c.branch}, {"event_index", c.event},
                                  {"text", curve_text(c, result, run)}};
    if (c.curve) {
        out.update({{"event", name(c.curve->event)}, {"start_index", c.curve->start},
                    {"ends", {c.curve->first_end, c.curve->last_end}}});
    }
    out["points"] = nlohmann::ordered_json::array();
    if (!c.curve) return out;
    for (const EventCurvePoint& pt : c.curve->points) {
        const BranchPoint& b = pt.point;
        nlohmann::ordered_json j = {{p, pt.first}, {q, pt.second}, {"xi", b.representative.xi}, {"U", b.representative.U},
                                    {"W", b.representative.W}, {"lambda", b.lambda}};
        j["eigenvalues"] = eigenvalues_json(b.eigenvalues);
        j.update({{"stability", name(b.stability)}, {"note", b.note}, {"point", xi_u_w(b.point)}, {"residual", b.residual},
                  {"bracket", b.bracket}});
        out["points"].push_back(std::move(j));
    }
    return out;
}

}  // namespace

std::string continuation_json(const ContinuationResult& result, const ContinuationRun& run, int ranks)
{
    const Model& m = run.model;
    const ContinuationSettings& s = run.settings;
    nlohmann::ordered_json out;
    out["model"] = model_json(m);
    out.update({{"parameter", name(run.parameter)}, {"min", s.min}, {"max", s.max}, {"ranks", ranks},
                {"step", s.initial_step}, {"min_step", s.min_step}, {"max_step", s.max_step}, {"max_points", s.max_points}});
    if (run.start) {
        out["start"] = {{"xi", run.start->xi}, {"U", run.start->U}, {"W", run.start->W}, {"period", run.period}};
    } else {
        out["search"] = {{"max_period", run.search.max_period}, {"starts", run.search.starts}, {"seed", run.search.seed},
                         {"corner", run.search.corner}};
    }
    out["branches"] = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < result.branches.size(); ++i) {
        out["branches"].push_back(branch_json(i, result.branches[i], std::string(name(run.parameter))));
    }
    if (run.curves) {
        out.update({{"curve_parameter", name(run.curves->second)}, {"curve_min", run.curves->settings.min2},
                    {"curve_max", run.curves->settings.max2}});
        out["curves"] = nlohmann::ordered_json::array();
        for (std::size_t i = 0; i < result.curves.size(); ++i) out["curves"].push_back(curve_json(i, result.curves[i], result, run));
    }
    return out.dump(1) + "\n";
}

}  // namespace superball::cli
