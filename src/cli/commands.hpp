// The subcommands of `superball`. Each registers itself on the top-level app and returns
// the function that runs it once the command line is parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace superball::cli {

// Returns the process exit status. Throws InputError for bad input (status 2).
using Runner = std::function<int()>;

Runner add_count_command(CLI::App& app);
Runner add_trajectory_command(CLI::App& app);
Runner add_explore_command(CLI::App& app);
Runner add_info_command(CLI::App& app);
Runner add_analyse_command(CLI::App& app);
Runner add_fixed_points_command(CLI::App& app);
Runner add_continue_command(CLI::App& app);

}  // namespace superball::cli
