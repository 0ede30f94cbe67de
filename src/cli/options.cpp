#include "options.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>

namespace superball::cli {

std::string flag_spelling(std::string_view key)
{
    std::string s = "--";
    for (const char c : key) s += c == '_' ? '-' : c;
    return s;
}

void add_model_flags(CLI::App& app, ModelInput& in)
{
    const std::string e_help = std::string("normal coefficient of restitution, ") + e_range_text;
    const std::string a_help = std::string("tangential coefficient of restitution, ") + alpha_range_text +
                               " (-1 smooth, 1 perfectly rough)";
    app.add_option("--e", in.e, e_help + ", both surfaces")->group("Model");
    app.add_option("--alpha", in.alpha, a_help + ", both surfaces")->group("Model");
    app.add_option("--e-wall", in.e_wall, "wall's e (overrides --e)")->group("Model");
    app.add_option("--alpha-wall", in.alpha_wall, "wall's alpha (overrides --alpha)")->group("Model");
    app.add_option("--e-floor", in.e_floor, "floor's e (overrides --e)")->group("Model");
    app.add_option("--alpha-floor", in.alpha_floor, "floor's alpha (overrides --alpha)")->group("Model");
}

void add_start_flags(CLI::App& app, StartFlags& in)
{
    const char* canonical = "Canonical start";
    app.add_option("--xi", in.xi, "g x / (2 |u| v): launch distance as a fraction of the free-flight range, > 0")
        ->group(canonical);
    app.add_option("--U", in.U, "u / v: launch direction, < 0")->group(canonical);
    app.add_option("--W", in.W, "a omega / v: spin relative to the vertical speed")->group(canonical);
    const char* physical = "Physical start";
    app.add_option("--x", in.x, "distance of the centre from the wall [m], > 0")->group(physical);
    app.add_option("--u", in.u, "horizontal velocity [m/s], < 0 (toward the wall)")->group(physical);
    app.add_option("--v", in.v, "vertical velocity [m/s], > 0")->group(physical);
    app.add_option("--omega", in.omega, "spin [rad/s], counter-clockwise positive")->group(physical);
    app.add_option("--g", in.g, "gravity [m/s^2] (default 9.81)")->group(physical);
    app.add_option("--radius", in.radius, "ball radius a [m] (default 0.025)")->group(physical);
}

void add_max_bounces_flag(CLI::App& app, std::uint32_t& max_bounces)
{
    app.add_option("--max-bounces", max_bounces, "stop after this many wall impacts (outcome capped)")
        ->check(CLI::Range(std::uint32_t{1}, std::uint32_t{4294967295u}))
        ->capture_default_str();
}

void write_output(const std::string& path, const std::function<void(std::FILE*)>& write)
{
    if (path.empty()) {
        write(stdout);
        return;
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "w"), &std::fclose);
    if (!file) throw std::runtime_error("cannot write " + path);
    write(file.get());
    if (std::fclose(file.release()) != 0) throw std::runtime_error("cannot write " + path);
}

namespace {

double require(const std::optional<double>& value, std::string_view key, std::string_view kind)
{
    if (!value) throw InputError(flag_spelling(key) + " is not set: a " + std::string(kind) + " start needs it");
    if (!std::isfinite(*value)) throw InputError(flag_spelling(key) + " = " + format_double(*value) + " is not a finite number");
    return *value;
}

void check(bool ok, std::string_view key, double value, std::string_view accepted)
{
    if (!ok) {
        throw InputError(flag_spelling(key) + " = " + format_double(value) + " is not a launch toward the wall: accepted " +
                         std::string(accepted));
    }
}

}  // namespace

Start resolve_start(const StartFlags& in)
{
    const bool any_canonical = in.xi || in.U || in.W;
    const bool any_physical = in.x || in.u || in.v || in.omega;
    if (any_canonical && any_physical) {
        throw InputError("give either a canonical start (--xi --U --W) or a physical one (--x --u --v --omega), not both");
    }
    if (!any_canonical && !any_physical) {
        throw InputError("no start point: give --xi --U --W (canonical) or --x --u --v --omega (physical)");
    }
    Start s;
    if (any_canonical) {
        if (in.g || in.radius) throw InputError("--g and --radius apply to physical starts only");
        s.canonical = {require(in.xi, "xi", "canonical"), require(in.U, "U", "canonical"), require(in.W, "W", "canonical")};
        check(s.canonical.xi > 0.0, "xi", s.canonical.xi, "xi > 0 (xi >= 1 misses the wall)");
        check(s.canonical.U < 0.0, "U", s.canonical.U, "U < 0");
        s.frame = {1.0, 1.0};
        s.state = to_physical(s.canonical, 1.0, 1.0);
        return s;
    }
    s.physical = true;
    s.frame.g = in.g.value_or(s.frame.g);
    s.frame.radius = in.radius.value_or(s.frame.radius);
    if (!(std::isfinite(s.frame.g) && s.frame.g > 0.0))
        throw InputError("--g = " + format_double(s.frame.g) + " is out of range: accepted g > 0");
    if (!(std::isfinite(s.frame.radius) && s.frame.radius > 0.0))
        throw InputError("--radius = " + format_double(s.frame.radius) + " is out of range: accepted radius > 0");
    const double omega = require(in.omega, "omega", "physical");
    s.state = {require(in.x, "x", "physical"), require(in.u, "u", "physical"), require(in.v, "v", "physical"),
               omega * s.frame.radius};
    check(s.state.x > 0.0, "x", s.state.x, "x > 0");
    check(s.state.u < 0.0, "u", s.state.u, "u < 0");
    check(s.state.v > 0.0, "v", s.state.v, "v > 0");
    s.canonical = to_canonical(s.state, s.frame.g);
    return s;
}

}  // namespace superball::cli
