#include "report.hpp"

namespace superball {

namespace {

// "key": value pairs, for the objects below.
class Fields {
public:
    explicit Fields(std::string& out) : out_(out) {}
    Fields& number(std::string_view key, double x) { return raw(key, format_double(x)); }
    Fields& integer(std::string_view key, std::uint64_t n) { return raw(key, std::to_string(n)); }
    Fields& text(std::string_view key, std::string_view s) { return raw(key, quote(s)); }
    Fields& raw(std::string_view key, std::string_view value)
    {
        out_ += first_ ? "" : ", ";
        first_ = false;
        out_ += quote(key);
        out_ += ": ";
        out_ += value;
        return *this;
    }

private:
    std::string& out_;
    bool first_ = true;
};

}  // namespace

std::string model_json(const Model& m)
{
    std::string out = "{";
    Fields(out)
        .number("e_wall", m.wall.e)
        .number("alpha_wall", m.wall.alpha)
        .number("e_floor", m.floor.e)
        .number("alpha_floor", m.floor.alpha);
    return out + "}";
}

std::string count_json(const BounceCount& r, const CanonicalState<double>& start)
{
    std::string out = "{";
    Fields(out)
        .integer("wall_bounces", r.wall_bounces)
        .text("outcome", name(r.outcome))
        .number("xi", start.xi)
        .number("U", start.U)
        .number("W", start.W);
    return out + "}\n";
}

std::string trajectory_json(const Trajectory& tr, const Start& start, const Model& m)
{
    const double a = start.frame.radius;
    std::string out = "{\n  ";
    Fields(out).text("units", start.physical ? "SI" : "dimensionless (v0 = g = radius = 1)");
    out += ",\n  ";
    Fields(out).number("g", start.frame.g).number("radius", a);
    out += ",\n  \"model\": " + model_json(m) + ",\n  \"start\": {";
    Fields(out).number("xi", start.canonical.xi).number("U", start.canonical.U).number("W", start.canonical.W);
    out += "},\n  ";
    Fields(out)
        .integer("wall_bounces", tr.result.wall_bounces)
        .text("outcome", name(tr.result.outcome))
        .raw("events_truncated", tr.truncated ? "true" : "false");
    out += ",\n  \"events\": [";
    const char* sep = "\n";
    for (const Event& e : tr.events) {
        out += sep;
        out += "    {";
        Fields(out)
            .text("event", name(e.kind))
            .integer("wall_bounces", e.wall_bounces)
            .number("t", e.t)
            .number("x", e.x)
            .number("y", e.y)
            .number("u_in", e.before.u)
            .number("v_in", e.before.v)
            .number("omega_in", e.before.W / a)
            .number("u", e.after.u)
            .number("v", e.after.v)
            .number("omega", e.after.W / a);
        out += "}";
        sep = ",\n";
    }
    out += "\n  ],\n  \"path\": [";
    sep = "\n";
    for (const PathPoint& p : tr.path) {
        out += sep;
        out += "    {";
        Fields(out).integer("segment", p.segment).number("t", p.t).number("x", p.x).number("y", p.y).number("u", p.u).number(
            "v", p.v);
        out += "}";
        sep = ",\n";
    }
    out += "\n  ]\n}\n";
    return out;
}

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
