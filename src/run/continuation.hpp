// Continuation of many branches over MPI (`superball continue`): the branches of the
// cycles the fixed-point search finds (or of one given start), shared among the ranks.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/continuation.hpp"
#include "core/input.hpp"
#include "core/event_curve.hpp"
#include "mpi/mpi.hpp"
#include "run/cycles.hpp"

namespace superball {

struct ContinuationRun {
    Model model;  // the start's coefficients
    Parameter parameter = Parameter::alpha;
    ContinuationSettings settings;
    // A point near the cycle to continue (xi = 0: on the corner plane), refined by Newton's
    // method for G^period first; without it, every cycle the search finds (periods
    // 1..search.max_period) starts a branch.
    std::optional<CanonicalState<double>> start;
    std::string start_key = "start";  // how the user spells it, for the message if no cycle is found there
    int period = 1;
    CycleSearch search;
    // Also follow every fold, period-doubling, Neimark-Sacker and branch point of the
    // branches as a curve in the plane (parameter, curves->second).
    struct Curves {
        Parameter second;
        EventCurveSettings settings;
    };
    std::optional<Curves> curves;
};

// A continuation as the user asks for it (the command line's flags, the Python call's
// arguments), before it is checked: resolve_continuation() makes the run.
struct ContinuationInput {
    ModelInput model;
    std::string param;                  // the coefficient continued in
    std::optional<double> min, max;     // its bounds
    std::optional<CanonicalState<double>> start;  // a point near the cycle (xi = 0: corner plane)
    int period = 1;
    std::int64_t starts = 2000;
    std::uint64_t seed = 1;
    bool corner = false;
    std::optional<double> step;         // default: min(0.01, max_step)
    double max_step = 0.05;
    double min_step = 1e-7;
    int max_points = 2000;
    std::string curve;                  // empty: no event curves
    std::optional<double> curve_min, curve_max;
    double curve_step = 0.005;
    double curve_max_step = 0.02;
    int curve_max_points = 400;
};

// "e, alpha, e_wall, alpha_wall, e_floor, alpha_floor": the coefficients a run continues in.
std::string parameter_list();

// The run `in` asks for; InputError naming the key as `spell` writes it ("--max-step" on
// the command line, "max_step" in Python), its value and what is accepted.
ContinuationRun resolve_continuation(const ContinuationInput& in, const KeySpelling& spell);

struct ContinuedBranch {
    Cycle start;
    // nullopt when the start is not a regular point of the branch equations.
    std::optional<Branch> branch;
    // The start lies on an earlier branch (index into the result): not continued again.
    std::optional<std::size_t> same_as;
};

struct ContinuedCurve {
    std::size_t branch;  // index of the branch (ContinuationResult::branches)
    std::size_t event;   // index of the event in its points
    // nullopt when no curve could be followed from it.
    std::optional<EventCurve> curve;
};

struct ContinuationResult {
    std::vector<ContinuedBranch> branches;  // in the order of their starts
    std::vector<ContinuedCurve> curves;     // by branch, then along it; only with run.curves
};

// Collective over `comm`: branch i is continued on rank i mod size, then event curve j on
// rank j mod size. Returns on rank 0 (empty elsewhere), the same for any number of ranks.
// Throws InputError when `start` does not converge to a cycle.
ContinuationResult continue_branches(const ContinuationRun& run, const mpi::Comm& comm);
// The same in this process alone, no MPI (the Python module's continue_branch()).
ContinuationResult continue_branches(const ContinuationRun& run);

}  // namespace superball
