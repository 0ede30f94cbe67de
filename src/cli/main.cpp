// superball: regions of initial conditions of a superball bouncing between a floor and a wall.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "commands.hpp"
#include "core/input.hpp"
#include "core/kernels.hpp"
#include "job/spelling.hpp"
#include "superball/version.hpp"

namespace {

bool is_number(std::string_view arg)
{
    const std::string text(arg);
    char* end = nullptr;
    std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size();
}

// CLI11 reports an unknown flag as "arguments were not expected: VALUE --FLAG", values
// and flags mixed. Name the first argument that looks like a flag yet is none of
// `command`'s (or the top level's), and the flag it most likely meant.
std::optional<std::string> unknown_flag_message(const CLI::App& app, const CLI::App& command, int argc, char** argv)
{
    std::vector<std::string> known;
    for (const CLI::App* a : {&app, &command}) {
        for (const CLI::Option* o : a->get_options()) {
            for (const std::string& n : o->get_lnames()) known.push_back("--" + n);
            for (const std::string& n : o->get_snames()) known.push_back("-" + n);
        }
    }
    const auto is_known = [&](std::string_view name) {
        return std::find(known.begin(), known.end(), name) != known.end();
    };
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--") break;
        if (arg.size() < 2 || arg[0] != '-' || is_number(arg)) continue;
        const std::string_view name = arg.substr(0, arg.find('='));
        // -ofile: a short flag with its value attached.
        if (is_known(name) || (arg[1] != '-' && is_known(arg.substr(0, 2)))) continue;
        const auto near = superball::suggestion(name, known);
        return fmt::format("superball {}: unknown option {} ({})", command.get_name(), name,
                           near ? "did you mean " + *near + "?" : "see superball " + command.get_name() + " --help");
    }
    return std::nullopt;
}

}  // namespace

int main(int argc, char** argv)
{
    using namespace superball;
    CLI::App app{"superball: how many times a spinning superball bounces between a floor and a wall\n"
                 "(Cross impact model) before it escapes, for one start or a whole grid of starts.",
                 "superball"};
    // The kernel line names the instruction set a run here would count with (SUPERBALL_KERNEL
    // included), for bug reports and for checking a node's binary.
    app.set_version_flag("--version", [] { return std::string("superball ") + software_version + "\n" + kernel_report(); });
    app.require_subcommand(1);
    app.footer("Run `superball COMMAND --help` for the options of a command. Exit status: 0 success,\n"
               "2 bad input (the message names it), 1 other failure.");

    std::map<const CLI::App*, cli::Runner> runners;
    for (auto add : {cli::add_explore_command, cli::add_count_command, cli::add_trajectory_command,
                     cli::add_info_command, cli::add_analyse_command, cli::add_fixed_points_command,
                     cli::add_continue_command}) {
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
        const auto chosen = app.get_subcommands();
        if (argc > 1 && argv[1][0] != '-' && chosen.empty()) {
            // CLI11 says "a subcommand is required" for a misspelt command: name it instead.
            std::vector<std::string> commands;
            for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
            const auto near = suggestion(argv[1], commands);
            fmt::print(stderr, "superball: unknown command '{}' ({})\n", argv[1],
                       near ? "did you mean " + *near + "?" : fmt::format("commands: {}; see --help", fmt::join(commands, ", ")));
            return 2;
        }
        const auto unknown = dynamic_cast<const CLI::ExtrasError*>(&e) == nullptr || chosen.empty()
                                 ? std::nullopt
                                 : unknown_flag_message(app, *chosen.front(), argc, argv);
        if (unknown) {
            fmt::print(stderr, "{}\n", *unknown);
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
