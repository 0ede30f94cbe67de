#include "view.hpp"

#include <cmath>
#include <limits>

namespace superball::serve {

namespace {

// The API spells every key as it is named in the query string.
std::string as_is(std::string_view key) { return std::string(key); }

std::vector<std::string> axis_list() { return {axis_names.begin(), axis_names.end()}; }

int parse_axis(Query& q, std::string_view key, std::string_view role)
{
    const std::optional<std::string> name = q.choice(key, axis_list());
    if (!name) refuse(std::string(key) + " is not set: accepted " + either(axis_list()) + " (the axis " + std::string(role) + ")");
    for (int k = 0; k < 3; ++k) {
        if (axis_names[static_cast<std::size_t>(k)] == *name) return k;
    }
    refuse(std::string(key) + " = " + *name + " is not accepted");  // not reached: choice() checked it
}

// TOML has integers and floats; a coordinate is a float, so "-1" is written "-1.0" (an
// integer as large as 1e19 would not even read back).
std::string toml_float(double x)
{
    std::string s = format_double(x);
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
}

Range parse_range(Query& q, std::string_view axis, const std::string& name, bool sizes)
{
    const std::string lo = std::string(axis) + "_min", hi = std::string(axis) + "_max";
    std::string n_key = "n";  // "n" + std::string(axis) draws a false -Wrestrict from GCC 12
    n_key += axis;
    const std::string needs = sizes ? lo + ", " + hi + " and " + n_key : lo + " and " + hi;
    const std::optional<double> min = q.finite(lo);
    if (!min) refuse(lo + " is not set: the range of " + name + " along " + std::string(axis) + " needs " + needs);
    const std::optional<double> max = q.finite(hi);
    if (!max) refuse(hi + " is not set: the range of " + name + " along " + std::string(axis) + " needs " + needs);
    std::uint64_t n = 1;
    if (sizes) {
        const auto given = q.integer(n_key, 1, std::numeric_limits<std::int64_t>::max(), n_key + " >= 1");
        if (!given) refuse(n_key + " is not set: the range of " + name + " along " + std::string(axis) + " needs " + needs);
        n = static_cast<std::uint64_t>(*given);
    }
    const std::string both = lo + " = " + format_double(*min) + " and " + hi + " = " + format_double(*max);
    if (!(*min < *max)) refuse(both + ": accepted " + lo + " < " + hi);
    if (!std::isfinite(*max - *min)) refuse(both + ": " + hi + " - " + lo + " overflows, accepted a finite width");
    const Range r{*min, *max, n};
    if (!std::isfinite(r.sample(n - 1))) {
        refuse(both + " with " + n_key + " = " + std::to_string(n) + ": the samples overflow, accepted (" + n_key +
               " - 0.5)(" + hi + " - " + lo + ") finite");
    }
    return r;
}

}  // namespace

ModelInput parse_model_input(Query& q)
{
    ModelInput in;
    for (const ModelKey& key : model_input_keys) in.*key.member = q.number(key.name);
    return in;
}

Model parse_model(Query& q, ModelInput& input)
{
    input = parse_model_input(q);
    try {
        return resolve_model(input, as_is);
    } catch (const InputError& e) {
        refuse(e.what());
    }
}

std::uint32_t parse_max_bounces(Query& q, std::uint32_t limit)
{
    const std::string accepted = "1 to " + std::to_string(limit) +
                                 " (the server's limit: larger caps are for superball explore and count)";
    return static_cast<std::uint32_t>(q.integer("max_bounces", 1, limit, accepted).value_or(1000));
}

Start parse_start(Query& q)
{
    const StartInput in{q.number("xi"), q.number("U"),     q.number("W"), q.number("x"),     q.number("u"),
                        q.number("v"),  q.number("omega"), q.number("g"), q.number("radius")};
    try {
        return resolve_start(in, as_is);
    } catch (const InputError& e) {
        refuse(e.what());
    }
}

View parse_view(Query& q, const Limits& limits, bool sizes)
{
    View v;
    v.plane.x = parse_axis(q, "x", "across");
    v.plane.y = parse_axis(q, "y", "up");
    const auto name = [](int k) { return std::string(axis_names[static_cast<std::size_t>(k)]); };
    if (v.plane.x == v.plane.y) {
        refuse("x = " + name(v.plane.x) + " and y = " + name(v.plane.y) +
               " are the same axis: accepted two different axes of xi, U, W");
    }
    v.plane.fixed = 3 - v.plane.x - v.plane.y;
    for (const auto& [axis, k] : {std::pair{"x", v.plane.x}, std::pair{"y", v.plane.y}}) {
        if (q.has(name(k))) {
            refuse(name(k) + " is given, but it is the " + axis + " axis: its range is " + axis + "_min, " + axis +
                   "_max; accepted a value for the third coordinate " + name(v.plane.fixed) + " only");
        }
    }
    const std::optional<double> fixed = q.finite(name(v.plane.fixed));
    if (!fixed) {
        refuse(name(v.plane.fixed) + " is not set: the third coordinate needs a fixed value (x = " + name(v.plane.x) +
               ", y = " + name(v.plane.y) + ")");
    }
    v.fixed = *fixed;
    v.x = parse_range(q, "x", name(v.plane.x), sizes);
    v.y = parse_range(q, "y", name(v.plane.y), sizes);
    v.model = parse_model(q, v.model_input);
    v.max_bounces = parse_max_bounces(q, limits.max_bounces);
    return v;
}

View tile_view(const View& window, int z, std::int64_t tx, std::int64_t ty, std::uint64_t n)
{
    View v = window;
    const double w = std::ldexp(window.x.max - window.x.min, -z);
    const double h = std::ldexp(window.y.max - window.y.min, -z);
    v.x = {window.x.min + static_cast<double>(tx) * w, window.x.min + static_cast<double>(tx + 1) * w, n};
    v.y = {window.y.max - static_cast<double>(ty + 1) * h, window.y.max - static_cast<double>(ty) * h, n};
    for (const auto& [r, k] : {std::pair{&v.x, window.plane.x}, std::pair{&v.y, window.plane.y}}) {
        bool distinct = std::isfinite(r->min) && std::isfinite(r->max) && r->min < r->max;
        for (std::uint64_t i = 0; distinct && i + 1 < n; ++i) distinct = r->sample(i) < r->sample(i + 1);
        if (!distinct) {
            refuse("z = " + std::to_string(z) + ": the tile's " + std::to_string(n) + " samples of " +
                   std::string(axis_names[static_cast<std::size_t>(k)]) + " in [" + format_double(r->min) + ", " +
                   format_double(r->max) + "] are not distinct doubles: accepted a zoom at which they are (double "
                   "precision ends there)");
        }
    }
    return v;
}

std::string job_toml(const View& v, std::string_view output, std::string_view comment)
{
    const auto name = [](int k) { return std::string(axis_names[static_cast<std::size_t>(k)]); };
    std::string t = "# A view of superball serve: " + name(v.plane.x) + " across, " + name(v.plane.y) + " up, at " +
                    name(v.plane.fixed) + " = " + format_double(v.fixed) + ".\n";
    t += "# Run it with: mpirun -n RANKS superball explore THIS.toml\n";
    t += "#          or: sbatch -n RANKS -t HH:MM:SS jobs/slurm/explore.sbatch THIS.toml\n";
    t += comment;
    t += "\n[model]\n";
    for (const ModelKey& key : model_input_keys) {
        if (const std::optional<double>& value = v.model_input.*key.member) {
            t += std::string(key.name) + " = " + toml_float(*value) + "\n";
        }
    }
    t += "\n[grid]\ncoordinates = \"canonical\"\n";
    for (int k = 0; k < 3; ++k) {
        const Range* r = k == v.plane.x ? &v.x : k == v.plane.y ? &v.y : nullptr;
        t += name(k) + " = ";
        t += r ? "{ min = " + toml_float(r->min) + ", max = " + toml_float(r->max) + ", n = " + std::to_string(r->n) + " }"
               : toml_float(v.fixed);
        t += "\n";
    }
    t += "\n[run]\nmax_bounces = " + std::to_string(v.max_bounces) + "\n";
    if (!output.empty()) t += "output = " + quote(output) + "\n";
    return t;
}

Job job_of(const View& v)
{
    try {
        return parse_job(job_toml(v, ""), "the view as a job");
    } catch (const InputError& e) {
        refuse(e.what());
    }
}

}  // namespace superball::serve
