// The work pool (work_pool.hpp) over MPI: which ranks serve which, found with
// MPI_Comm_split_type (one leader per node when the ranks span several nodes), and the
// messages between them.
#pragma once

#include <cstdint>
#include <span>

#include "mpi/mpi.hpp"
#include "run/work_pool.hpp"

namespace superball {

struct ScheduleResult {
    bool interrupted = false;  // on every rank: tiles were left undone on purpose
    ScheduleStats stats;       // this rank's
};

// Collective over `comm`. `pending` (identical on every rank): the tiles to compute, in
// the order they are handed out; consecutive entries form the blocks.
ScheduleResult run_schedule(const mpi::Comm& comm, std::span<const std::uint64_t> pending, TileWork& work,
                            const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings = {});

}  // namespace superball
