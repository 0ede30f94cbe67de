// Continuation of many branches over MPI (`superball continue`): the branches of the
// cycles the fixed-point search finds (or of one given start), shared among the ranks.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "core/continuation.hpp"
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
};

struct ContinuedBranch {
    Cycle start;
    // nullopt when the start is not a regular point of the branch equations.
    std::optional<Branch> branch;
    // The start lies on an earlier branch (index into the result): not continued again.
    std::optional<std::size_t> same_as;
};

// Collective over `comm`: branch i is continued on rank i mod size. Returns the branches
// on rank 0 in the order of their starts (empty elsewhere), the same for any number of
// ranks. Throws InputError when `start` does not converge to a cycle.
std::vector<ContinuedBranch> continue_branches(const ContinuationRun& run, const mpi::Comm& comm);

}  // namespace superball
