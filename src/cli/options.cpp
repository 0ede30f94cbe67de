#include "options.hpp"

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

Start resolve_start(const StartFlags& in) { return superball::resolve_start(in, flag_spelling); }

}  // namespace superball::cli
