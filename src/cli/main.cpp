// superball: regions of initial conditions of a superball bouncing between a floor and a wall.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <cstdio>
#include <exception>
#include <map>

#include "commands.hpp"
#include "core/input.hpp"
#include "superball/version.hpp"

int main(int argc, char** argv)
{
    using namespace superball;
    CLI::App app{"superball: how many times a spinning superball bounces between a floor and a wall\n"
                 "(Cross impact model) before it escapes, for one start or a whole grid of starts.",
                 "superball"};
    app.set_version_flag("--version", std::string("superball ") + software_version);
    app.require_subcommand(1);
    app.footer("Run `superball COMMAND --help` for the options of a command. Exit status: 0 success,\n"
               "2 bad input (the message names it), 1 other failure.");

    std::map<const CLI::App*, cli::Runner> runners;
    for (auto add : {cli::add_explore_command, cli::add_count_command, cli::add_trajectory_command,
                     cli::add_info_command, cli::add_analyse_command, cli::add_fixed_points_command}) {
        auto run = add(app);
        runners.emplace(app.get_subcommands({}).back(), std::move(run));
    }

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // CLI11 says "a subcommand is required" for a misspelt command: name it instead.
        if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty()) {
            fmt::print(stderr,
                       "superball: unknown command '{}' (commands: explore, count, trajectory, info, analyse, fixed-points; see --help)\n",
                       argv[1]);
        } else {
            fmt::print(stderr, "superball: {} (run with --help for usage)\n", e.what());
        }
        return 2;
    }
    const CLI::App* chosen = app.get_subcommands().front();
    try {
        return runners.at(chosen)();
    } catch (const InputError& e) {
        fmt::print(stderr, "superball {}: {}\n", chosen->get_name(), e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "superball {}: error: {}\n", chosen->get_name(), e.what());
        return 1;
    }
}
