// superball._core's dynamics: fixed_points() and continue_branch() (run/cycles.hpp,
// run/continuation.hpp).
#include <pybind11/complex.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "run/continuation.hpp"
#include "run/cycles.hpp"

namespace py = pybind11;

namespace superball {
namespace {

py::tuple state_tuple(const CanonicalState<double>& s) { return py::make_tuple(s.xi, s.U, s.W); }

py::list eigenvalue_list(const std::array<std::complex<double>, 3>& ev) { return py::cast(std::vector(ev.begin(), ev.end())); }

py::dict cycle_dict(const Cycle& c)
{
    py::dict d;
    d["period"] = c.period;
    d["xi"] = c.points.front().xi;
    d["U"] = c.points.front().U;
    d["W"] = c.points.front().W;
    d["lambda"] = c.lambda;
    d["eigenvalues"] = eigenvalue_list(c.eigenvalues);
    d["stability"] = std::string(name(c.stability));
    d["family"] = c.family;
    d["corner"] = c.corner;
    d["residual"] = c.residual;
    py::list points;
    for (const CanonicalState<double>& p : c.points) points.append(state_tuple(p));
    d["points"] = points;
    return d;
}

// fixed_points(): every distinct cycle, as fixed-points prints it.
py::list fixed_point_list(const ModelInput& given, int period, std::int64_t starts, std::uint64_t seed, bool corner)
{
    const Model model = resolve_model(given, python_key);
    const CycleSearch search{period, starts, seed, corner};
    check_cycle_search(search, python_key);
    std::vector<Cycle> cycles;
    {
        const py::gil_scoped_release release;
        cycles = find_cycles(model, search);
    }
    py::list out;
    for (const Cycle& c : cycles) out.append(cycle_dict(c));
    return out;
}

py::tuple point_row(const BranchPoint& q)
{
    const auto& ev = q.eigenvalues;
    return py::make_tuple(q.parameter, q.representative.xi, q.representative.U, q.representative.W, q.lambda, ev[0].real(),
                          ev[0].imag(), ev[1].real(), ev[1].imag(), ev[2].real(), ev[2].imag(), std::string(name(q.stability)),
                          std::string(name(q.event)), q.note, q.residual, q.arclength, q.bracket);
}

// continue_branch(): the branches (rows as the CSV's, without the branch's columns) and
// the event curves, as continue prints them.
py::dict continuation(const ContinuationInput& in)
{
    const ContinuationRun run = resolve_continuation(in, python_key);
    ContinuationResult result;
    {
        const py::gil_scoped_release release;
        result = continue_branches(run);
    }
    py::list branches;
    for (const ContinuedBranch& b : result.branches) {
        py::dict d;
        d["start"] = cycle_dict(b.start);
        d["same_as"] = b.same_as ? py::cast(*b.same_as) : py::object(py::none());
        d["continued"] = b.branch.has_value();
        py::list rows;
        if (b.branch) {
            d["period"] = b.branch->period;
            d["corner"] = b.branch->domain == Domain::corner;
            d["start_index"] = b.branch->start;
            for (const BranchPoint& q : b.branch->points) rows.append(point_row(q));
        }
        d["points"] = rows;
        branches.append(d);
    }
    py::dict out;
    out["parameter"] = std::string(name(run.parameter));
    out["branches"] = branches;
    if (run.curves) {
        out["curve_parameter"] = std::string(name(run.curves->second));
        py::list curves;
        for (const ContinuedCurve& c : result.curves) {
            py::dict d;
            d["branch"] = c.branch;
            d["event_index"] = c.event;
            py::list rows;
            if (c.curve) {
                d["event"] = std::string(name(c.curve->event));
                d["period"] = c.curve->period;
                d["corner"] = c.curve->domain == Domain::corner;
                d["ends"] = py::make_tuple(c.curve->first_end, c.curve->last_end);
                for (const EventCurvePoint& p : c.curve->points) rows.append(py::make_tuple(p.first, p.second, point_row(p.point)));
            }
            d["points"] = rows;
            curves.append(d);
        }
        out["curves"] = curves;
    }
    return out;
}

}  // namespace

void add_dynamics(py::module_& m)
{
    m.def("fixed_points", &fixed_point_list, py::arg("model"), py::arg("period"), py::arg("starts"), py::arg("seed"),
          py::arg("corner"));
    m.def(
        "continue_branch",
        [](const ModelInput& model, const std::string& param, std::optional<double> min,
           std::optional<double> max, std::optional<std::array<double, 3>> start, int period, std::int64_t starts,
           std::uint64_t seed, bool corner, std::optional<double> step, double max_step, double min_step, int max_points,
           const std::string& curve, std::optional<double> curve_min, std::optional<double> curve_max, double curve_step,
           double curve_max_step, int curve_max_points) {
            ContinuationInput in;
            in.model = model;
            in.param = param;
            in.min = min;
            in.max = max;
            if (start) in.start = CanonicalState<double>{(*start)[0], (*start)[1], (*start)[2]};
            in.period = period;
            in.starts = starts;
            in.seed = seed;
            in.corner = corner;
            in.step = step;
            in.max_step = max_step;
            in.min_step = min_step;
            in.max_points = max_points;
            in.curve = curve;
            in.curve_min = curve_min;
            in.curve_max = curve_max;
            in.curve_step = curve_step;
            in.curve_max_step = curve_max_step;
            in.curve_max_points = curve_max_points;
            return continuation(in);
        },
        py::arg("model"), py::arg("param"), py::arg("min"), py::arg("max"), py::arg("start"), py::arg("period"), py::arg("starts"),
        py::arg("seed"), py::arg("corner"), py::arg("step"), py::arg("max_step"), py::arg("min_step"), py::arg("max_points"),
        py::arg("curve"), py::arg("curve_min"), py::arg("curve_max"), py::arg("curve_step"), py::arg("curve_max_step"),
        py::arg("curve_max_points"));
}

}  // namespace superball
