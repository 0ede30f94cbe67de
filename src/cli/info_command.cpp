#include <fmt/core.h>

#include <memory>

#include "commands.hpp"
#include "core/count.hpp"
#include "io/result_file.hpp"

namespace superball::cli {

Runner add_info_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("info", "Describe a result file: job, shape, completeness, outcomes");
    auto path = std::make_shared<std::string>();
    sub->add_option("file", *path, "result file (.h5) written by superball explore")->required();
    return [path] {
        h5::silence_errors();
        if (!std::filesystem::exists(*path)) throw InputError(*path + ": no such file");
        ResultInfo info;
        try {
            info = read_result_info(*path);
        } catch (const h5::Error& e) {
            throw InputError(*path + " is not a superball result (" + e.what() + ")");
        }
        std::uint64_t points = 1;
        std::string shape;
        for (std::size_t k = 0; k < info.shape.size(); ++k) {
            points *= info.shape[k];
            shape += fmt::format("{}{} {}", k ? " x " : "", info.shape[k], info.axis_names[k]);
        }
        fmt::print("file:        {}\n", *path);
        fmt::print("coordinates: {}\n", info.coordinates);
        fmt::print("grid:        {} ({} points)\n", shape, points);
        fmt::print("complete:    {} ({} of {} tiles done)\n", info.complete ? "yes" : "no", info.tiles_done, info.tiles);
        fmt::print("max_bounces: {}\n", info.max_bounces);
        fmt::print("written by:  superball {} on {} rank{}, {:.2f} s in all\n", info.software_version, info.mpi_ranks,
                   info.mpi_ranks == 1 ? "" : "s", info.wall_seconds);
        const std::vector<std::uint64_t> h = outcome_histogram(*path);
        fmt::print("outcomes{}:\n", info.complete ? "" : " (tiles not yet done read as invalid)");
        for (int o = 0; o < outcome_count; ++o) {
            const auto n = h[static_cast<std::size_t>(o)];
            fmt::print("  {:<8} {:>14} {:8.3f}%\n", name(static_cast<Outcome>(o)), n,
                       100.0 * static_cast<double>(n) / static_cast<double>(points));
        }
        fmt::print("job:\n{}", info.job_toml);
        if (!info.job_toml.empty() && info.job_toml.back() != '\n') fmt::print("\n");
        return 0;
    };
}

}  // namespace superball::cli
