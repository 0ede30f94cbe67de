#include "event_curve.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "input.hpp"

namespace superball {

namespace {

// Half-width of the transversal line, in steps: the prediction's error is O(h^2 curvature).
constexpr double line_half_width = 2.0;
// The event found within this fraction of a step from the prediction: the next step grows.
constexpr double easy_fraction = 0.25;
constexpr double curve_growth = 1.5;

struct Plane {
    Model model;  // the other coefficients
    Parameter first, second;
};

// Coefficients (q1, q2) + s (n1, n2), the others those of the model.
ParameterPath line(const Plane& plane, double q1, double q2, double n1, double n2)
{
    return {with_parameter(with_parameter(plane.model, plane.first, q1), plane.second, q2),
            with_parameter(with_parameter(no_change, plane.first, n1), plane.second, n2), "s"};
}

struct Found {
    double first, second;
    BranchPoint point;
    double s;  // along the line from the prediction
    // Folds: the unit vector in the plane, across the curve, toward the side where the
    // cycles exist (the branch turns back there); zero for other events.
    Eigen::Vector2d side = Eigen::Vector2d::Zero();
};

// For a fold at points[i] of a branch along `along` (a unit vector of the plane): which way
// along it the branch's neighbouring points lie.
Eigen::Vector2d fold_side(const std::vector<BranchPoint>& points, std::size_t i, const Eigen::Vector2d& along)
{
    const std::size_t j = i > 0 ? i - 1 : i + 1;
    if (j >= points.size()) return Eigen::Vector2d::Zero();
    return points[j].parameter > points[i].parameter ? along : Eigen::Vector2d(-along);
}

// What is traced: an event of a cycle of some period, in a domain of the map.
struct Sought {
    BranchEvent event;
    int period;
    Domain domain;
};

// A line of the plane: the points q + s n.
struct PlaneLine {
    double q1, q2;  // its origin
    double n1, n2;  // a unit vector along it
};

// The event sought on `on` nearest to its origin, following the cycle through the
// predicted state from s = s0 on the line, within half_width of the origin.
std::optional<Found> locate_on_line(const Plane& plane, const Sought& sought, const CanonicalState<double>& predicted,
                                    const PlaneLine& on, double s0, double half_width)
{
    const auto [event, period, domain] = sought;
    const auto [q1, q2, n1, n2] = on;
    const ParameterPath path = line(plane, q1, q2, n1, n2);
    const ModelMatrices m = ModelMatrices::of(path.at(s0));
    const auto point = newton_cycle(predicted, m, period, domain);
    const auto cycle = point ? make_cycle(*point, m, period, domain) : std::nullopt;
    if (!cycle || cycle->period != period) return std::nullopt;
    ContinuationSettings s;
    s.min = std::min(-half_width, s0);
    s.max = std::max(half_width, s0);
    s.initial_step = half_width / 8.0;
    s.max_step = half_width / 4.0;
    s.min_step = half_width * 1e-6;
    s.max_points = 400;
    const auto branch = continue_cycle(*cycle, path, s0, s);
    if (!branch) return std::nullopt;
    std::optional<Found> best;
    for (std::size_t i = 0; i < branch->points.size(); ++i) {
        const BranchPoint& p = branch->points[i];
        if (p.event != event) continue;
        if (best && std::abs(best->s) <= std::abs(p.parameter)) continue;
        best = Found{q1 + p.parameter * n1, q2 + p.parameter * n2, p, p.parameter};
        if (event == BranchEvent::fold) best->side = fold_side(branch->points, i, Eigen::Vector2d(n1, n2));
    }
    return best;
}

struct HalfCurve {
    std::vector<Found> points;
    std::string end;
};

bool inside(const EventCurveSettings& set, double a, double b)
{
    return a >= set.min1 && a <= set.max1 && b >= set.min2 && b <= set.max2;
}

HalfCurve trace(const Plane& plane, const Found& start, double sign, const Sought& sought, const EventCurveSettings& set)
{
    const BranchEvent event = sought.event;
    HalfCurve d;
    Found last = start;
    double h = set.initial_step;
    // First step: along the second coefficient, the line along the first.
    Eigen::Vector2d direction(0.0, sign);
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // d(state)/d(plane arclength)
    while (true) {
        if (static_cast<int>(d.points.size()) >= set.max_points) {
            d.end = "point limit " + std::to_string(set.max_points) + " reached";
            return d;
        }
        const double q1 = last.first + h * direction(0), q2 = last.second + h * direction(1);
        if (!inside(set, q1, q2)) {
            d.end = "the next step leaves the bounds of " + std::string(name(plane.first)) + " and " +
                    std::string(name(plane.second));
            return d;
        }
        const Eigen::Vector3d x = as_vector(last.point.point) + h * velocity;
        // The transversal line, for a fold pointing to the side where the cycles exist; the
        // prediction may fall on the other side, so the cycle is looked for up to 2h inside.
        Eigen::Vector2d n(-direction(1), direction(0));
        if (n.dot(last.side) < 0.0) n = -n;
        std::optional<Found> found;
        for (const double s0 : {0.0, 0.5, 1.0, 2.0}) {
            if (s0 > 0.0 && event != BranchEvent::fold) break;
            found = locate_on_line(plane, sought, as_state(x), {q1, q2, n(0), n(1)}, s0 * h, line_half_width * h);
            if (found) break;
        }
        if (!found || !inside(set, found->first, found->second)) {
            h *= 0.5;
            if (h < set.min_step) {
                d.end = "no " + std::string(name(event)) + " found near the prediction at steps down to " +
                        format_double(set.min_step);
                return d;
            }
            continue;
        }
        const Eigen::Vector2d step(found->first - last.first, found->second - last.second);
        const double length = step.norm();
        if (!(length > 0.0)) {
            d.end = "the curve does not advance";
            return d;
        }
        velocity = (as_vector(found->point.point) - as_vector(last.point.point)) / length;
        direction = step / length;
        if (std::abs(found->s) < easy_fraction * h) h = std::min(h * curve_growth, set.max_step);
        d.points.push_back(*found);
        last = *found;
    }
}

EventCurvePoint curve_point(const Found& f)
{
    EventCurvePoint p{f.first, f.second, f.point};
    p.point.parameter = f.first;
    p.point.arclength = 0.0;
    return p;
}

}  // namespace

bool independent(Parameter a, Parameter b)
{
    // Every coefficient each moves (mu and inertia too: mu and mu_wall both move the wall's).
    const auto ma = model_coefficients(with_parameter(no_change, a, 1.0));
    const auto mb = model_coefficients(with_parameter(no_change, b, 1.0));
    return std::inner_product(ma.begin(), ma.end(), mb.begin(), 0.0) == 0.0;
}

std::optional<EventCurve> continue_event(const Branch& branch, std::size_t index, const Model& model, Parameter first,
                                         Parameter second, const EventCurveSettings& settings)
{
    if (index >= branch.points.size() || !independent(first, second)) return std::nullopt;
    const BranchPoint& e = branch.points[index];
    const bool curve_event = e.event == BranchEvent::fold || e.event == BranchEvent::period_doubling ||
                             e.event == BranchEvent::neimark_sacker || e.event == BranchEvent::branch_point;
    if (!curve_event) return std::nullopt;
    const Plane plane{with_parameter(model, first, e.parameter), first, second};
    Found start{e.parameter, parameter_value(model, second), e, 0.0};
    if (e.event == BranchEvent::fold) start.side = fold_side(branch.points, index, Eigen::Vector2d(1.0, 0.0));
    const Sought sought{e.event, branch.period, branch.domain};
    const HalfCurve up = trace(plane, start, 1.0, sought, settings);
    const HalfCurve down = trace(plane, start, -1.0, sought, settings);
    if (up.points.empty() && down.points.empty()) return std::nullopt;
    EventCurve c;
    c.event = e.event;
    c.period = branch.period;
    c.domain = branch.domain;
    for (auto it = down.points.rbegin(); it != down.points.rend(); ++it) c.points.push_back(curve_point(*it));
    c.start = c.points.size();
    c.points.push_back(curve_point(start));
    for (const Found& f : up.points) c.points.push_back(curve_point(f));
    c.first_end = down.end;
    c.last_end = up.end;
    return c;
}

}  // namespace superball
