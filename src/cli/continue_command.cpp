// superball continue: branches of cycles of the canonical map followed in one coefficient
// (pseudo-arclength continuation), with their folds, bifurcations and ends.
#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "continue_command.hpp"
#include "every_rank.hpp"
#include "continuation_output.hpp"
#include "core/continuation.hpp"
#include "mpi/mpi.hpp"
#include "options.hpp"
#include "run/continuation.hpp"
#include "core/event_curve.hpp"
#include "job/provenance.hpp"

namespace superball::cli {

namespace {

// "xi,U,W" as three numbers (resolve_continuation checks they are a launch).
CanonicalState<double> parse_start(const std::string& text)
{
    std::vector<double> v;
    std::size_t from = 0;
    while (from <= text.size()) {
        const std::size_t comma = std::min(text.find(',', from), text.size());
        const std::string field = text.substr(from, comma - from);
        double x = 0.0;
        const auto r = std::from_chars(field.data(), field.data() + field.size(), x);
        if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size() || !std::isfinite(x)) {
            throw InputError("--start = " + text + " is not three numbers: accepted xi,U,W, e.g. 0.25,-0.56,-1.36");
        }
        v.push_back(x);
        from = comma + 1;
    }
    if (v.size() != 3) throw InputError("--start = " + text + " is not three numbers: accepted xi,U,W, e.g. 0.25,-0.56,-1.36");
    return {v[0], v[1], v[2]};
}

ContinuationRun resolve(const ContinueOptions& opt)
{
    ContinuationInput in = opt.in;
    if (!opt.start.empty()) in.start = parse_start(opt.start);
    ContinuationRun run = resolve_continuation(in, flag_spelling);
    if (opt.format != "csv" && opt.format != "json") {
        throw InputError("--format = " + opt.format + " is not a format: accepted csv or json");
    }
    return run;
}

}  // namespace

int continue_command(const ContinueOptions& opt)
{
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    // For the CSV header: the run as it starts (collective: every rank counts the hosts).
    const Provenance prov{process_command_line(), utc_now(), world.size(), mpi::host_count(world), 1, ""};
    ContinuationRun cont;
    ContinuationResult result;
    const int status = on_every_rank("continue", world, [&] {
        cont = resolve(opt);
        result = continue_branches(cont, world);
        return 0;
    });
    // The output after the ranks are done with each other: a file that cannot be written
    // ends rank 0 alone (main's error path).
    if (status != 0 || !world.is_root()) return status;

    write_output(opt.output, [&](std::FILE* f) {
        if (opt.format == "json") {
            fmt::print(f, "{}", continuation_json(result, cont, world.size()));
        } else if (cont.curves) {
            write_curves_csv(f, result, cont, prov);
        } else {
            write_branches_csv(f, result, cont, prov);
        }
    });
    return 0;
}

}  // namespace superball::cli
