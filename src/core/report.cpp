#include "report.hpp"

namespace superball {

std::vector<TrajectoryRow> trajectory_rows(const Trajectory& tr, double radius)
{
    std::vector<TrajectoryRow> rows;
    rows.reserve(tr.events.size() + tr.path.size());
    for (const Event& e : tr.events) {
        rows.push_back({name(e.kind), e.wall_bounces, e.t, e.x, e.y, e.before.u, e.before.v, e.before.W / radius, e.after.u,
                        e.after.v, e.after.W / radius});
    }
    for (const PathPoint& p : tr.path) {
        const Event& from = tr.events[p.segment];
        const double omega = from.after.W / radius;
        rows.push_back({"path", from.wall_bounces, p.t, p.x, p.y, p.u, p.v, omega, p.u, p.v, omega});
    }
    return rows;
}

}  // namespace superball
