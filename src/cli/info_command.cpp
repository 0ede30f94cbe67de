// superball info: what a result or partial file says about itself, validated.
#include <fmt/core.h>

#include <algorithm>
#include <string_view>
#include <utility>

#include "info_command.hpp"
#include "core/count.hpp"
#include "io/layout.hpp"
#include "io/result_reader.hpp"

namespace superball::cli {

int info_command(const InfoOptions& opt)
{
    std::filesystem::path p = opt.file;
    std::error_code ec;
    const bool unfinished = !std::filesystem::exists(p, ec) && std::filesystem::exists(layout::partial_path(p), ec);
    if (unfinished) p = layout::partial_path(p);
    const ResultReader reader(p);
    const ResultInfo& info = reader.info();
    // Every value is read (and checked) before anything is printed: a damaged file gets
    // one message, not half a report.
    const OutcomeCounts h = reader.outcome_counts();
    if (unfinished) fmt::print("{} does not exist yet: its run is not finished; its partial file:\n", opt.file.c_str());
    std::string shape;
    for (std::size_t k = 0; k < info.shape.size(); ++k) {
        shape += fmt::format("{}{} {}", k ? " x " : "", info.shape[k], info.axis_names[k]);
    }
    fmt::print("file:        {}\n", p.string());
    fmt::print("kind:        {}\n", info.kind == FileKind::result ? "result" : "partial (a run in progress or interrupted)");
    fmt::print("coordinates: {}\n", info.coordinate_system);
    fmt::print("grid:        {} ({} points)\n", shape, info.points());
    if (info.kind == FileKind::result) {
        fmt::print("complete:    yes\n");
    } else {
        fmt::print("complete:    no ({} of {} tiles done)\n", info.tiles_done, info.tiles);
        fmt::print("to finish:   superball explore JOB --resume (the same job and output)\n");
    }
    fmt::print("max_bounces: {}\n", info.max_bounces);
    fmt::print("written by:  superball {} on {} rank{}{}, {:.2f} s in all\n", info.software_version, info.mpi_ranks,
               info.mpi_ranks == 1 ? "" : "s", info.threads > 1 ? fmt::format(" of {} threads", info.threads) : "",
               info.wall_seconds);
    // Provenance (CF/ACDD attributes), where the file has it.
    for (const auto& [label, text] : {std::pair{"source:", &info.source}, std::pair{"created:", &info.date_created},
                                      std::pair{"build:", &info.build}}) {
        if (!text->empty()) fmt::print("{:<13}{}\n", label, *text);
    }
    if (!info.history.empty()) {
        fmt::print("history:\n");
        std::size_t from = 0;
        while (from < info.history.size()) {
            const std::size_t end = std::min(info.history.find('\n', from), info.history.size());
            fmt::print("  {}\n", std::string_view(info.history).substr(from, end - from));
            from = end + 1;
        }
    }
    fmt::print("outcomes{}:\n", h.not_computed ? " (of the points computed so far)" : "");
    const std::uint64_t computed = info.points() - h.not_computed;
    for (int o = 0; o < outcome_count; ++o) {
        const auto n = h.by_outcome[static_cast<std::size_t>(o)];
        fmt::print("  {:<12} {:>14} {:8.3f}%\n", name(static_cast<Outcome>(o)), n,
                   computed ? 100.0 * static_cast<double>(n) / static_cast<double>(computed) : 0.0);
    }
    if (h.not_computed) {
        fmt::print("  {:<12} {:>14} {:8.3f}% of the grid\n", "not computed", h.not_computed,
                   100.0 * static_cast<double>(h.not_computed) / static_cast<double>(info.points()));
    }
    fmt::print("job:\n{}", info.job_toml);
    if (!info.job_toml.empty() && info.job_toml.back() != '\n') fmt::print("\n");
    return 0;
}

}  // namespace superball::cli
