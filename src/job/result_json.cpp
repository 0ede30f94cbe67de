#include "result_json.hpp"

#include <cmath>

#include "core/trajectory.hpp"

namespace superball {

// SPEC.md 1b's coefficients where not their defaults, as model_text() and a result's
// attributes have them (so the Cross model of a solid ball prints as before, and no mu is
// infinite: JSON has no infinity).
nlohmann::ordered_json model_json(const Model& m)
{
    nlohmann::ordered_json out = {
        {"e_wall", m.wall.e}, {"alpha_wall", m.wall.alpha}, {"e_floor", m.floor.e}, {"alpha_floor", m.floor.alpha}};
    if (m.frictional()) {
        out["mu_wall"] = std::isfinite(m.wall.mu) ? nlohmann::ordered_json(m.wall.mu) : nlohmann::ordered_json("inf");
        out["mu_floor"] = std::isfinite(m.floor.mu) ? nlohmann::ordered_json(m.floor.mu) : nlohmann::ordered_json("inf");
    }
    if (m.inertia != solid_ball_inertia) out["inertia"] = m.inertia;
    return out;
}

std::string count_json(const BounceCount& r, const CanonicalState<double>& start)
{
    const nlohmann::ordered_json out = {{"wall_bounces", r.wall_bounces}, {"outcome", name(r.outcome)},
                                        {"xi", start.xi}, {"U", start.U}, {"W", start.W}};
    return out.dump() + "\n";
}

std::string trajectory_json(const Trajectory& tr, const Start& start, const Model& m)
{
    const double a = start.frame.radius;
    nlohmann::ordered_json out = {{"units", start.physical ? "SI" : "dimensionless (v0 = g = radius = 1)"},
                                  {"g", start.frame.g},
                                  {"radius", a},
                                  {"model", model_json(m)},
                                  {"start", {{"xi", start.canonical.xi}, {"U", start.canonical.U}, {"W", start.canonical.W}}},
                                  {"wall_bounces", tr.result.wall_bounces},
                                  {"outcome", name(tr.result.outcome)},
                                  {"events_truncated", tr.truncated}};
    nlohmann::ordered_json& events = out["events"] = nlohmann::ordered_json::array();
    for (const Event& e : tr.events) {
        nlohmann::ordered_json& event = events.emplace_back();
        event = {{"event", name(e.kind)},
                          {"wall_bounces", e.wall_bounces},
                          {"t", e.t},
                          {"x", e.x},
                          {"y", e.y},
                          {"u_in", e.before.u},
                          {"v_in", e.before.v},
                          {"omega_in", e.before.W / a},
                          {"u", e.after.u},
                          {"v", e.after.v},
                          {"omega", e.after.W / a}};
        // Impacts (SPEC.md 1b): whether each gripped or slid, and its tangential factor.
        if (e.kind == EventKind::wall || e.kind == EventKind::floor) {
            event["contact"] = e.contact.slid ? "slide" : "grip";
            event["beta"] = e.contact.beta;
        }
    }
    nlohmann::ordered_json& path = out["path"] = nlohmann::ordered_json::array();
    for (const PathPoint& p : tr.path) {
        path.push_back({{"segment", p.segment}, {"t", p.t}, {"x", p.x}, {"y", p.y}, {"u", p.u}, {"v", p.v}});
    }
    return out.dump(1) + "\n";
}

}  // namespace superball
