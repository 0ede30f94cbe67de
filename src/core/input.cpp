#include "input.hpp"

#include <charconv>
#include <cstdio>

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

}  // namespace

Model resolve_model(const ModelInput& in, const KeySpelling& spell)
{
    return {{pick(in.e_wall, in.e, "e_wall", "e", true, spell), pick(in.alpha_wall, in.alpha, "alpha_wall", "alpha", false, spell)},
            {pick(in.e_floor, in.e, "e_floor", "e", true, spell),
             pick(in.alpha_floor, in.alpha, "alpha_floor", "alpha", false, spell)}};
}

}  // namespace superball
