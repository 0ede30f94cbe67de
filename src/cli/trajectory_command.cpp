#include <fmt/core.h>
#include <fmt/os.h>

#include "trajectory_command.hpp"
#include "core/report.hpp"
#include "job/result_json.hpp"
#include "core/trajectory.hpp"
#include "options.hpp"

namespace superball::cli {

namespace {

// Every double is printed with the shortest text that reads back to the same value.
void write_csv(std::FILE* f, const Trajectory& tr, double radius)
{
    fmt::print(f, "{}\n", trajectory_columns);
    for (const TrajectoryRow& r : trajectory_rows(tr, radius)) {
        fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{},{},{}\n", r.event, r.wall_bounces, r.t, r.x, r.y, r.u_in, r.v_in,
                   r.omega_in, r.u, r.v, r.omega, r.contact, r.beta);
    }
}

}  // namespace

int trajectory_command(const TrajectoryOptions& opt)
{
    const OneStartSetup setup = resolve_one_start(opt.model, opt.start, opt.max_bounces, flag_spelling);
    const Model& model = setup.model;
    const Start start = resolve_start(opt.start);
    if (opt.samples == 1) throw InputError("--samples = 1 is out of range: accepted 0 or 2..100000");
    const Trajectory tr = trajectory(start.state, model, start.frame.g, setup.max_bounces, opt.samples);
    write_output(opt.output, [&](std::FILE* f) {
        if (opt.format == "json") {
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
}

}  // namespace superball::cli
