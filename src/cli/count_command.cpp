#include <fmt/core.h>

#include <memory>

#include "commands.hpp"
#include "core/count.hpp"
#include "core/report.hpp"
#include "job/result_json.hpp"
#include "options.hpp"

namespace superball::cli {

namespace {
struct CountOptions {
    ModelInput model;
    StartFlags start;
    std::uint32_t max_bounces = 1000;
    bool json = false;
};
}  // namespace

Runner add_count_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("count", "Count the wall bounces of one start point");
    sub->footer(
        "Example: superball count --xi 0.05 --U -1 --W -2 --e 0.9 --alpha 0.9\n"
        "Prints the number of wall impacts and the outcome: left (the ball moved away from the wall),\n"
        "missed (it landed on the floor before reaching the wall), capped (--max-bounces reached),\n"
        "invalid (not a launch toward the wall).");
    auto opt = std::make_shared<CountOptions>();
    add_model_flags(*sub, opt->model);
    add_start_flags(*sub, opt->start);
    add_max_bounces_flag(*sub, opt->max_bounces);
    sub->add_flag("--json", opt->json, "print a JSON object instead of a sentence");
    return [opt] {
        const Model model = resolve_model(opt->model, flag_spelling);
        const Start start = resolve_start(opt->start);
        const BounceCount r = count(start.canonical, model, opt->max_bounces);
        if (opt->json) {
            fmt::print("{}", count_json(r, start.canonical));
        } else {
            fmt::print("{} wall bounce{}, outcome {}\n", r.wall_bounces, r.wall_bounces == 1 ? "" : "s", name(r.outcome));
        }
        return 0;
    };
}

}  // namespace superball::cli
