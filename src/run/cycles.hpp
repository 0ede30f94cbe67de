// The parallel search for cycles of the canonical map G (`superball fixed-points`): Newton's
// method from many seeded starts, the starts shared among MPI ranks.
#pragma once

#include <cstdint>
#include <vector>

#include "core/dynamics.hpp"
#include "core/input.hpp"
#include "mpi/mpi.hpp"

namespace superball {

struct CycleSearch {
    int max_period = 1;         // periods 1..max_period
    std::int64_t starts = 2000; // Newton starts, drawn by SeededStarts(seed)
    std::uint64_t seed = 1;
    bool corner = false;        // also search the corner plane xi = 0
};

inline constexpr int max_cycle_period = 8;

// InputError unless 1 <= max_period <= max_cycle_period and starts >= 1, naming the key
// ("period", "starts") as `spell` writes it.
void check_cycle_search(const CycleSearch& search, const KeySpelling& spell);

// Collective over `comm`. Every rank tries its share of the starts; the distinct cycles
// are returned on rank 0 (empty elsewhere), the same for any number of ranks: rank 0
// examines the hits in the order of a serial run.
std::vector<Cycle> find_cycles(const Model& model, const CycleSearch& search, const mpi::Comm& comm);
// The same search in this process alone, no MPI (the Python module's fixed_points()): the
// cycles a run on any number of ranks returns.
std::vector<Cycle> find_cycles(const Model& model, const CycleSearch& search);

}  // namespace superball
