#include "report.hpp"

#include <limits>

namespace superball {

std::vector<TrajectoryRow> trajectory_rows(const Trajectory& tr, double radius)
{
    std::vector<TrajectoryRow> rows;
    rows.reserve(tr.events.size() + tr.path.size());
    constexpr double none = std::numeric_limits<double>::quiet_NaN();
    for (const Event& e : tr.events) {
        const bool impact = e.kind == EventKind::wall || e.kind == EventKind::floor;
        rows.push_back({name(e.kind), e.wall_bounces, e.t, e.x, e.y, e.before.u, e.before.v, e.before.W / radius, e.after.u,
                        e.after.v, e.after.W / radius, impact ? (e.contact.slid ? "slide" : "grip") : "",
                        impact ? e.contact.beta : none});
    }
    for (const PathPoint& p : tr.path) {
        const Event& from = tr.events[p.segment];
        const double omega = from.after.W / radius;
        rows.push_back({"path", from.wall_bounces, p.t, p.x, p.y, p.u, p.v, omega, p.u, p.v, omega, "", none});
    }
    return rows;
}

}  // namespace superball
