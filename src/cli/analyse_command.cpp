// superball analyse: the options, analyse_result (run/analyse.hpp), the output
// (analysis_output.hpp).
#include <memory>
#include <optional>
#include <string>

#include "analysis_output.hpp"
#include "commands.hpp"
#include "core/input.hpp"
#include "run/analyse.hpp"

namespace superball::cli {

namespace {

struct AnalyseOptions {
    std::string file;
    std::string slice;
    std::size_t box = 5;
    std::optional<std::size_t> eps_max;
    std::optional<std::size_t> box_max;
    std::size_t top = 5;
    bool with_outcome = false;
    bool json = false;
};

// "AXIS=INDEX", e.g. "U=0" or "1=0".
Slice parse_slice(const std::string& text)
{
    const auto eq = text.find('=');
    const std::string index = eq == std::string::npos ? "" : text.substr(eq + 1);
    if (eq == 0 || index.empty() || index.find_first_not_of("0123456789") != std::string::npos || index.size() > 18) {
        throw InputError("--slice: expected AXIS=INDEX (an axis name or number and a sample index, e.g. U=0), got '" +
                         text + "'");
    }
    return {text.substr(0, eq), std::stoull(index)};
}

}  // namespace

Runner add_analyse_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("analyse", "Structure of the regions of a 2-D result: areas, boundaries, fractal dimension, "
                                              "basin entropy");
    sub->footer(
        "The class of a point is its wall-bounce count (with --with-outcome: count and outcome);\n"
        "points with outcome invalid belong to no class. Reports area fractions, the length of\n"
        "the boundaries between classes, the uncertainty exponent alpha (the fraction of points with\n"
        "another class within e cells along their row or column ~ e^alpha) and D = 2 - alpha, the\n"
        "box-counting dimension of the boundary, and the basin entropy S_b, S_bb (Daza et al. 2016).\n"
        "The file is read a band of rows at a time: memory grows with the row length, not the grid.\n"
        "Example: superball analyse results/quickstart.h5 --json");
    auto opt = std::make_shared<AnalyseOptions>();
    sub->add_option("file", opt->file, "result file (.h5) written by superball explore")->required();
    sub->add_option("--slice", opt->slice, "the plane of a 3-D result: AXIS=INDEX, e.g. U=0 (required for 3-D results)");
    sub->add_option("--box", opt->box, "side of the basin-entropy boxes, in points")
        ->check(CLI::Range(std::size_t{1}, std::size_t{4096}))
        ->capture_default_str();
    sub->add_option("--eps-max", opt->eps_max,
                    "largest distance e (cells) for the uncertainty exponent; e = 1, 2, 4, ... up to it "
                    "(default: min(rows, cols)/64, at least 2)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--box-max", opt->box_max,
                    "largest box side s (cells) for box counting; s = 1, 2, 4, ... up to it (default: min(rows, cols)/16)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--top", opt->top, "pairs of classes listed by boundary length")->capture_default_str();
    sub->add_flag("--with-outcome", opt->with_outcome, "classes are (count, outcome) pairs, not counts alone");
    sub->add_flag("--json", opt->json, "print a JSON object instead of a report");
    return [opt] {
        AnalyseRequest request{opt->file, std::nullopt, opt->with_outcome ? ClassRule::count_and_outcome : ClassRule::count,
                               opt->box, opt->eps_max, opt->box_max, opt->top};
        if (!opt->slice.empty()) request.slice = parse_slice(opt->slice);
        const Analysis analysis = analyse_result(request);
        if (opt->json) {
            print_analysis_json(opt->file, analysis, request.slice);
        } else {
            print_analysis_report(opt->file, analysis, request.slice);
        }
        return 0;
    };
}

}  // namespace superball::cli
