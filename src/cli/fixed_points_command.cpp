// superball fixed-points: fixed points and cycles of the canonical map G (self-similar
// motions), by Newton's method from many seeded starts, split across MPI ranks.
#include <fmt/core.h>

#include <complex>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "fixed_points_command.hpp"
#include "every_rank.hpp"
#include "job/result_json.hpp"
#include "core/dynamics.hpp"
#include "mpi/mpi.hpp"
#include "run/cycles.hpp"
#include "options.hpp"

namespace superball::cli {

namespace {

void validate(const FixedPointOptions& opt)
{
    check_cycle_search({opt.period, opt.starts, opt.seed, opt.corner}, flag_spelling);
    if (opt.format != "table" && opt.format != "json") {
        throw InputError("--format = " + opt.format + " is not a format: accepted table or json");
    }
}

std::string eigenvalue_text(const std::complex<double>& z)
{
    if (z.imag() == 0.0) return fmt::format("{:.10g}", z.real());
    return fmt::format("{:.10g}{:+.10g}i", z.real(), z.imag());
}

void write_table(std::FILE* f, const std::vector<Cycle>& cycles, const Model& model, const FixedPointOptions& opt,
                 int ranks)
{
    fmt::print(f, "# superball fixed-points: {}\n", model_text(model));
    fmt::print(f, "# periods 1..{}{}, {} Newton starts (seed {}) on {} rank{}: {} cycle{}\n", opt.period,
               opt.corner ? " (also on the corner plane xi = 0)" : "", opt.starts, opt.seed, ranks, ranks == 1 ? "" : "s",
               cycles.size(), cycles.size() == 1 ? "" : "s");
    fmt::print(f, "# (xi, U, W): the point of the cycle with the smallest xi; lambda: product of the multipliers\n"
                  "# over the cycle; eig1..3: eigenvalues of the Jacobian of G^period; family: eigenvalue 1,\n"
                  "# the cycle belongs to a continuous family; corner: on the plane xi = 0\n");
    fmt::print(f, "{:>6} {:>23} {:>23} {:>23} {:>20} {:>36} {:>36} {:>36} {:>9} {:>6} {:>6}\n", "period", "xi", "U", "W",
               "lambda", "eig1", "eig2", "eig3", "stability", "family", "corner");
    for (const Cycle& c : cycles) {
        const CanonicalState<double>& p = c.points.front();
        fmt::print(f, "{:>6} {:>23.16g} {:>23.16g} {:>23.16g} {:>20.14g} {:>36} {:>36} {:>36} {:>9} {:>6} {:>6}\n",
                   c.period, p.xi, p.U, p.W, c.lambda, eigenvalue_text(c.eigenvalues[0]),
                   eigenvalue_text(c.eigenvalues[1]), eigenvalue_text(c.eigenvalues[2]), name(c.stability),
                   c.family ? "yes" : "no", c.corner ? "yes" : "no");
    }
}

// JSON through nlohmann-json: doubles as the shortest text that reads back to the same value.
void write_json(std::FILE* f, const std::vector<Cycle>& cycles, const Model& model, const FixedPointOptions& opt,
                int ranks)
{
    using Json = nlohmann::ordered_json;
    Json out;
    out["model"] = model_json(model);
    out.update({{"max_period", opt.period}, {"starts", opt.starts}, {"seed", opt.seed}, {"corner_search", opt.corner},
                {"ranks", ranks}, {"residual_tolerance", residual_tolerance}, {"marginal_tolerance", marginal_tolerance}});
    out["cycles"] = Json::array();
    for (const Cycle& c : cycles) {
        const CanonicalState<double>& p = c.points.front();
        Json cycle = {{"period", c.period}, {"xi", p.xi}, {"U", p.U}, {"W", p.W}, {"lambda", c.lambda},
                      {"stability", name(c.stability)}, {"family", c.family}, {"corner", c.corner}, {"residual", c.residual}};
        cycle["eigenvalues"] = Json::array();
        for (const std::complex<double>& z : c.eigenvalues) cycle["eigenvalues"].push_back({{"re", z.real()}, {"im", z.imag()}});
        cycle["points"] = Json::array();
        for (const CanonicalState<double>& q : c.points) cycle["points"].push_back({{"xi", q.xi}, {"U", q.U}, {"W", q.W}});
        out["cycles"].push_back(std::move(cycle));
    }
    fmt::print(f, "{}\n", out.dump(1));
}

}  // namespace

int fixed_points_command(const FixedPointOptions& opt)
{
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    Model model;
    std::vector<Cycle> cycles;
    const int status = on_every_rank("fixed-points", world, [&] {
        model = resolve_model(opt.model, flag_spelling);
        validate(opt);
        cycles = find_cycles(model, {opt.period, opt.starts, opt.seed, opt.corner}, world);
        return 0;
    });
    // The output after the ranks are done with each other: a file that cannot be written
    // ends rank 0 alone (main's error path).
    if (status != 0 || !world.is_root()) return status;

    write_output(opt.output, [&](std::FILE* f) {
        if (opt.format == "json") {
            write_json(f, cycles, model, opt, world.size());
        } else {
            write_table(f, cycles, model, opt, world.size());
        }
    });
    return 0;
}

}  // namespace superball::cli
