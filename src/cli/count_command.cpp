#include <fmt/core.h>

#include "count_command.hpp"
#include "core/count.hpp"
#include "core/report.hpp"
#include "job/result_json.hpp"
#include "options.hpp"

namespace superball::cli {

int count_command(const CountOptions& opt)
{
    const OneStartSetup setup = resolve_one_start(opt.model, opt.start, opt.max_bounces, flag_spelling);
    const Start start = resolve_start(opt.start);
    const BounceCount r = count(start.canonical, setup.model, setup.max_bounces);
    if (opt.json) {
        fmt::print("{}", count_json(r, start.canonical));
    } else {
        fmt::print("{} wall bounce{}, outcome {}\n", r.wall_bounces, r.wall_bounces == 1 ? "" : "s", name(r.outcome));
    }
    return 0;
}

}  // namespace superball::cli
