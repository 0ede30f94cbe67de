// The parallel search for cycles of the canonical map G (`superball fixed-points`): Newton's
// method from many seeded starts, the starts shared among MPI ranks.
#pragma once

#include <cstdint>
#include <vector>

#include "core/dynamics.hpp"
#include "mpi/mpi.hpp"

namespace superball {

struct CycleSearch {
    int max_period = 1;         // periods 1..max_period
    std::int64_t starts = 2000; // Newton starts, drawn by SeededStarts(seed)
    std::uint64_t seed = 1;
    bool corner = false;        // also search the corner plane xi = 0
};

// Collective over `comm`. Every rank tries its share of the starts; the distinct cycles
// are returned on rank 0 (empty elsewhere), the same for any number of ranks: rank 0
// examines the hits in the order of a serial run.
std::vector<Cycle> find_cycles(const Model& model, const CycleSearch& search, const mpi::Comm& comm);

}  // namespace superball
