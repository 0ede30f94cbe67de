// superball analyse: the request from its options, analyse_result (run/analyse.hpp), the output
// (analysis_output.hpp).
#include <optional>
#include <string>

#include "analysis_output.hpp"
#include "analyse_command.hpp"
#include "core/input.hpp"
#include "run/analyse.hpp"

namespace superball::cli {

namespace {

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

int analyse_command(const AnalyseOptions& opt)
{
    AnalyseRequest request{opt.file, std::nullopt, opt.with_outcome ? ClassRule::count_and_outcome : ClassRule::count,
                           opt.box, opt.eps_max, opt.box_max, opt.top};
    if (!opt.slice.empty()) request.slice = parse_slice(opt.slice);
    const Analysis analysis = analyse_result(request);
    if (opt.json) {
        print_analysis_json(opt.file, analysis, request.slice);
    } else {
        print_analysis_report(opt.file, analysis, request.slice);
    }
    return 0;
}

}  // namespace superball::cli
