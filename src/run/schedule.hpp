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
// the order they are handed out; consecutive entries form the blocks. `writers`: every rank
// gives a sink or none does.
ScheduleResult run_schedule(const mpi::Comm& comm, std::span<const ListedTile> pending, TileWork& work,
                            const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings = {},
                            const Writers& writers = {});

// Collective over `comm`: how many ranks run_schedule with these settings (and Writers)
// makes writers of compressed tiles.
int schedule_writers(const mpi::Comm& comm, const ScheduleSettings& settings);

}  // namespace superball
