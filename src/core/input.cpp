#include "input.hpp"

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

double pick(const std::optional<double>& specific, const std::optional<double>& shared, std::string_view key,
            std::string_view shared_key, bool is_e, const KeySpelling& spell)
{
    const bool from_specific = specific.has_value();
    if (!from_specific && !shared) {
        throw InputError(spell(key) + " is not set: give " + spell(shared_key) + " (both surfaces) or " + spell(key));
    }
    const double value = from_specific ? *specific : *shared;
    const bool ok = is_e ? e_in_range(value) : alpha_in_range(value);
    if (!ok) {
        throw InputError(spell(from_specific ? key : shared_key) + " = " + format_double(value) +
                         " is out of range: accepted " + (is_e ? e_range_text : alpha_range_text));
    }
    return value;
}

double require(const std::optional<double>& value, std::string_view key, std::string_view kind, const KeySpelling& spell)
{
    if (!value) throw InputError(spell(key) + " is not set: a " + std::string(kind) + " start needs it");
    if (!std::isfinite(*value)) throw InputError(spell(key) + " = " + format_double(*value) + " is not a finite number");
    return *value;
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
    return {{pick(in.e_wall, in.e, "e_wall", "e", true, spell), pick(in.alpha_wall, in.alpha, "alpha_wall", "alpha", false, spell)},
            {pick(in.e_floor, in.e, "e_floor", "e", true, spell),
             pick(in.alpha_floor, in.alpha, "alpha_floor", "alpha", false, spell)}};
}

Start resolve_start(const StartInput& in, const KeySpelling& spell)
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
    Start s;
    if (any_canonical) {
        if (in.g || in.radius) throw InputError(spell("g") + " and " + spell("radius") + " apply to physical starts only");
        s.canonical = {require(in.xi, "xi", "canonical", spell), require(in.U, "U", "canonical", spell),
                       require(in.W, "W", "canonical", spell)};
        check_launch(s.canonical.xi > 0.0, "xi", s.canonical.xi, "xi > 0 (xi >= 1 misses the wall)", spell);
        check_launch(s.canonical.U < 0.0, "U", s.canonical.U, "U < 0", spell);
        s.frame = {1.0, 1.0};
        s.state = to_physical(s.canonical, 1.0, 1.0);
        return s;
    }
    s.physical = true;
    s.frame.g = in.g.value_or(s.frame.g);
    s.frame.radius = in.radius.value_or(s.frame.radius);
    if (!(std::isfinite(s.frame.g) && s.frame.g > 0.0))
        throw InputError(spell("g") + " = " + format_double(s.frame.g) + " is out of range: accepted g > 0");
    if (!(std::isfinite(s.frame.radius) && s.frame.radius > 0.0))
        throw InputError(spell("radius") + " = " + format_double(s.frame.radius) + " is out of range: accepted radius > 0");
    const double omega = require(in.omega, "omega", "physical", spell);
    s.state = {require(in.x, "x", "physical", spell), require(in.u, "u", "physical", spell),
               require(in.v, "v", "physical", spell), omega * s.frame.radius};
    check_launch(s.state.x > 0.0, "x", s.state.x, "x > 0", spell);
    check_launch(s.state.u < 0.0, "u", s.state.u, "u < 0", spell);
    check_launch(s.state.v > 0.0, "v", s.state.v, "v > 0", spell);
    s.canonical = to_canonical(s.state, s.frame.g);
    return s;
}

}  // namespace superball
