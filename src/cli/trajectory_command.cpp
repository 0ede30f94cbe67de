#include <fmt/core.h>
#include <fmt/os.h>

#include <memory>

#include "commands.hpp"
#include "core/report.hpp"
#include "job/result_json.hpp"
#include "core/trajectory.hpp"
#include "options.hpp"

namespace superball::cli {

namespace {

struct TrajectoryOptions {
    ModelInput model;
    StartFlags start;
    std::uint32_t max_bounces = 1000;
    std::string format = "csv";
    int samples = 0;
    std::string output;
};

// Every double is printed with the shortest text that reads back to the same value.
void write_csv(std::FILE* f, const Trajectory& tr, double radius)
{
    fmt::print(f, "{}\n", trajectory_columns);
    for (const TrajectoryRow& r : trajectory_rows(tr, radius)) {
        fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{}\n", r.event, r.wall_bounces, r.t, r.x, r.y, r.u_in, r.v_in, r.omega_in,
                   r.u, r.v, r.omega);
    }
}

}  // namespace

Runner add_trajectory_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("trajectory", "Print every impact of one start point (CSV or JSON)");
    sub->footer(
        "Events: launch, wall (impact), floor (bounce), land (the floor contact after the motion ended,\n"
        "recorded, not applied). Columns: time t, centre (x, y), velocities and spin arriving (_in) and\n"
        "leaving. A canonical start is followed in dimensionless units (v0 = g = radius = 1, so omega = W);\n"
        "a physical start in SI units. --samples K adds K points on every flight (event 'path') for plotting.");
    auto opt = std::make_shared<TrajectoryOptions>();
    add_model_flags(*sub, opt->model);
    add_start_flags(*sub, opt->start);
    add_max_bounces_flag(*sub, opt->max_bounces);
    sub->add_option("--format", opt->format, "csv or json")->check(CLI::IsMember({"csv", "json"}))->capture_default_str();
    sub->add_option("--samples", opt->samples, "points sampled on each flight parabola (0: none, otherwise >= 2)")
        ->check(CLI::Range(0, 100000));
    sub->add_option("-o,--output", opt->output, "write to this file instead of standard output");
    return [opt] {
        const Model model = resolve_model(opt->model, flag_spelling);
        const Start start = resolve_start(opt->start);
        if (opt->samples == 1) throw InputError("--samples = 1 is out of range: accepted 0 or 2..100000");
        const Trajectory tr = trajectory(start.state, model, start.frame.g, opt->max_bounces, opt->samples);
        write_output(opt->output, [&](std::FILE* f) {
            if (opt->format == "json") {
                fmt::print(f, "{}", trajectory_json(tr, start, model));
            } else {
                write_csv(f, tr, start.frame.radius);
            }
        });
        if (tr.truncated) {
            fmt::print(stderr,
                       "superball trajectory: events stop after wall impact {}: the motion converges into the corner "
                       "and its scale left double precision; the count ({} wall bounces, {}) is exact\n",
                       tr.events.back().wall_bounces, tr.result.wall_bounces, name(tr.result.outcome));
        }
        return 0;
    };
}

}  // namespace superball::cli
