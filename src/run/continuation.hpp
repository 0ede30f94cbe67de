// Continuation of many branches over MPI (`superball continue`): the branches of the
// cycles the fixed-point search finds (or of one given start), shared among the ranks.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "core/continuation.hpp"
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

}  // namespace superball
