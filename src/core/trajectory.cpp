#include "trajectory.hpp"

namespace superball {

namespace {

void sample_flight(std::vector<PathPoint>& path, std::uint32_t segment, const Event& from, double duration, double g,
                   int samples)
{
    const Velocities<double>& s = from.after;
    for (int k = 0; k < samples; ++k) {
        const double tau = duration * k / (samples - 1);
        path.push_back({segment, from.t + tau, from.x + s.u * tau, from.y + s.v * tau - 0.5 * g * tau * tau, s.u,
                        s.v - g * tau});
    }
}

}  // namespace

Trajectory trajectory(const PhysicalState<double>& start, const Model& model, double g, std::uint32_t max_bounces,
                      int samples_per_flight)
{
    Trajectory out;
    if (!is_launch(start) || !(g > 0.0)) {
        out.result = {0, Outcome::invalid};
        return out;
    }
    const ModelMatrices m = ModelMatrices::of(model);
    const int samples = samples_per_flight >= 2 ? samples_per_flight : 0;
    auto flight = [&](double duration) {
        if (samples == 0) return;
        const auto segment = static_cast<std::uint32_t>(out.events.size() - 1);
        sample_flight(out.path, segment, out.events.back(), duration, g, samples);
    };
    // The ball is on the floor and will land again after 2 v / g: the record ends there.
    auto land = [&](const PhysicalState<double>& s, double t, std::uint32_t n) {
        const double t_flight = 2.0 * s.v / g;
        flight(t_flight);
        const Velocities<double> arriving{s.u, -s.v, s.W};
        out.events.push_back({EventKind::land, n, t + t_flight, s.x + s.u * t_flight, 0.0, arriving, arriving});
    };

    PhysicalState<double> s = start;
    CanonicalState<double> c = to_canonical(start, g);
    double t = 0.0;
    std::uint32_t n = 0;
    const Velocities<double> v0{s.u, s.v, s.W};
    out.events.push_back({EventKind::launch, 0, 0.0, s.x, 0.0, v0, v0});
    for (;;) {
        if (!(c.xi < 1.0)) {
            if (!out.truncated) land(s, t, n);
            out.result = {n, Outcome::missed};
            return out;
        }
        if (n >= max_bounces) {
            out.result = {n, Outcome::capped};
            return out;
        }
        // Past the representable scale only the canonical state goes on, for the result.
        out.truncated = out.truncated || s.v < start.v * representable_scale;
        ++n;
        if (!out.truncated) {
            const Excursion<double> e = excursion(s, m, g);
            flight(e.to_wall.t);
            t += e.to_wall.t;
            const Velocities<double> at_wall{s.u, e.to_wall.v_w, s.W};
            out.events.push_back({EventKind::wall, n, t, 0.0, e.to_wall.y, at_wall, e.after_wall,
                                  contact(at_wall.v - at_wall.W, -at_wall.u, model.wall.alpha, m.wall)});
            flight(e.to_floor.t);
            t += e.to_floor.t;
            const Velocities<double> at_floor{e.after_wall.u, e.to_floor.v_f, e.after_wall.W};
            out.events.push_back({EventKind::floor, n, t, e.next.x, 0.0, at_floor, {e.next.u, e.next.v, e.next.W},
                                  contact(at_floor.u + at_floor.W, -at_floor.v, model.floor.alpha, m.floor)});
            s = e.next;
        }
        c = canonical_map(c, m).next;
        if (c.U >= 0.0) {
            if (!out.truncated) land(s, t, n);
            out.result = {n, Outcome::left};
            return out;
        }
    }
}

}  // namespace superball
