#include "input.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <initializer_list>

namespace superball {

std::string format_double(double x)
{
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return {buf, r.ptr};
}

std::string model_text(const Model& m)
{
    std::string out = "e_wall " + format_double(m.wall.e) + " alpha_wall " + format_double(m.wall.alpha) + " e_floor " +
                      format_double(m.floor.e) + " alpha_floor " + format_double(m.floor.alpha);
    if (m.frictional()) out += " mu_wall " + format_double(m.wall.mu) + " mu_floor " + format_double(m.floor.mu);
    if (m.inertia != solid_ball_inertia) out += " inertia " + format_double(m.inertia);
    return out;
}

std::string quote(std::string_view s)
{
    std::string out = "\"";
    for (const char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
                    out += buf;
                } else {
                    out += c;
                }
        }
    }
    return out + "\"";
}

namespace {

// What a coefficient accepts, for the range check and its message.
struct Accepted {
    bool (*in_range)(double);
    const char* text;
};

// A surface's coefficient: the per-surface key's value, else the shared key's, else
// `fallback` (none: the coefficient must be given).
double pick(const std::optional<double>& specific, const std::optional<double>& shared, std::string_view key,
            std::string_view shared_key, Accepted accepted, const KeySpelling& spell,
            std::optional<double> fallback = std::nullopt)
{
    const bool from_specific = specific.has_value();
    if (!from_specific && !shared) {
        if (fallback) return *fallback;
        throw InputError(spell(key) + " is not set: give " + spell(shared_key) + " (both surfaces) or " + spell(key));
    }
    const double value = from_specific ? *specific : *shared;
    if (!accepted.in_range(value)) {
        throw InputError(spell(from_specific ? key : shared_key) + " = " + format_double(value) +
                         " is out of range: accepted " + accepted.text);
    }
    return value;
}

double finite(double value, std::string_view key, const KeySpelling& spell)
{
    if (!std::isfinite(value)) throw InputError(spell(key) + " = " + format_double(value) + " is not a finite number");
    return value;
}

void check_launch(bool ok, std::string_view key, double value, std::string_view accepted, const KeySpelling& spell)
{
    if (!ok) {
        throw InputError(spell(key) + " = " + format_double(value) + " is not a launch toward the wall: accepted " +
                         std::string(accepted));
    }
}

}  // namespace

Model resolve_model(const ModelInput& in, const KeySpelling& spell)
{
    constexpr Accepted e{e_in_range, e_range_text}, alpha{alpha_in_range, alpha_range_text}, mu{mu_in_range, mu_range_text};
    const Surface defaults{};
    const Surface wall{pick(in.e_wall, in.e, "e_wall", "e", e, spell),
                       pick(in.alpha_wall, in.alpha, "alpha_wall", "alpha", alpha, spell),
                       pick(in.mu_wall, in.mu, "mu_wall", "mu", mu, spell, defaults.mu)};
    const Surface floor{pick(in.e_floor, in.e, "e_floor", "e", e, spell),
                        pick(in.alpha_floor, in.alpha, "alpha_floor", "alpha", alpha, spell),
                        pick(in.mu_floor, in.mu, "mu_floor", "mu", mu, spell, defaults.mu)};
    const double inertia = pick(in.inertia, std::nullopt, "inertia", "inertia", {inertia_in_range, inertia_range_text},
                                spell, solid_ball_inertia);
    return {wall, floor, inertia};
}

StartKind resolve_start_keys(const StartInput& in, const KeySpelling& spell)
{
    const auto keys = [&](std::initializer_list<std::string_view> names) {
        std::string out;
        for (const std::string_view n : names) {
            // Two appends: GCC 12 warns (-Wrestrict, a false positive, GCC bug 105329) on
            // `"literal" + std::string` inlined here.
            if (!out.empty()) out += ' ';
            out += spell(n);
        }
        return out;
    };
    const std::string canonical = keys({"xi", "U", "W"}), physical = keys({"x", "u", "v", "omega"});
    const bool any_canonical = in.xi || in.U || in.W;
    const bool any_physical = in.x || in.u || in.v || in.omega;
    if (any_canonical && any_physical) {
        throw InputError("give either a canonical start (" + canonical + ") or a physical one (" + physical + "), not both");
    }
    if (!any_canonical && !any_physical) {
        throw InputError("no start point: give " + canonical + " (canonical) or " + physical + " (physical)");
    }
    const auto require = [&](const std::optional<double>& value, std::string_view key, std::string_view kind) {
        if (!value) throw InputError(spell(key) + " is not set: a " + std::string(kind) + " start needs it");
    };
    StartKind k;
    if (any_canonical) {
        if (in.g || in.radius) throw InputError(spell("g") + " and " + spell("radius") + " apply to physical starts only");
        require(in.xi, "xi", "canonical");
        require(in.U, "U", "canonical");
        require(in.W, "W", "canonical");
        return k;
    }
    k.physical = true;
    k.frame = Frame{};
    k.frame.g = in.g.value_or(k.frame.g);
    k.frame.radius = in.radius.value_or(k.frame.radius);
    if (!(std::isfinite(k.frame.g) && k.frame.g > 0.0))
        throw InputError(spell("g") + " = " + format_double(k.frame.g) + " is out of range: accepted g > 0");
    if (!(std::isfinite(k.frame.radius) && k.frame.radius > 0.0))
        throw InputError(spell("radius") + " = " + format_double(k.frame.radius) + " is out of range: accepted radius > 0");
    require(in.omega, "omega", "physical");
    require(in.x, "x", "physical");
    require(in.u, "u", "physical");
    require(in.v, "v", "physical");
    return k;
}

Start resolve_start(const StartInput& in, const KeySpelling& spell)
{
    const StartKind kind = resolve_start_keys(in, spell);
    Start s;
    s.physical = kind.physical;
    s.frame = kind.frame;
    if (!kind.physical) {
        s.canonical = {finite(*in.xi, "xi", spell), finite(*in.U, "U", spell), finite(*in.W, "W", spell)};
        check_launch(s.canonical.xi > 0.0, "xi", s.canonical.xi, "xi > 0 (xi >= 1 misses the wall)", spell);
        check_launch(s.canonical.U < 0.0, "U", s.canonical.U, "U < 0", spell);
        s.state = to_physical(s.canonical, 1.0, 1.0);
        return s;
    }
    const double omega = finite(*in.omega, "omega", spell);
    s.state = {finite(*in.x, "x", spell), finite(*in.u, "u", spell), finite(*in.v, "v", spell), omega * s.frame.radius};
    check_launch(s.state.x > 0.0, "x", s.state.x, "x > 0", spell);
    check_launch(s.state.u < 0.0, "u", s.state.u, "u < 0", spell);
    check_launch(s.state.v > 0.0, "v", s.state.v, "v > 0", spell);
    s.canonical = to_canonical(s.state, s.frame.g);
    return s;
}

std::uint32_t resolve_max_bounces(std::string_view given, const KeySpelling& spell)
{
    const bool negative = !given.empty() && given.front() == '-';
    const std::string_view digits = negative ? given.substr(1) : given;
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        throw InputError(spell("max_bounces") + " = " + std::string(given) + " is not an integer");
    }
    std::uint64_t value = 0;
    const bool fits = std::from_chars(digits.data(), digits.data() + digits.size(), value).ec == std::errc{};
    if (negative || !fits || value < 1 || value > 4294967295u) {
        throw InputError(spell("max_bounces") + " = " + std::string(given) + " is out of range: accepted 1 to 4294967295");
    }
    return static_cast<std::uint32_t>(value);
}

OneStartSetup resolve_one_start(const ModelInput& model, const StartInput& start, std::string_view max_bounces,
                                const KeySpelling& spell)
{
    OneStartSetup s;
    s.model = resolve_model(model, spell);
    s.start = resolve_start_keys(start, spell);
    s.max_bounces = resolve_max_bounces(max_bounces, spell);
    return s;
}

}  // namespace superball
