// The one error path of the commands that run on every MPI rank (explore, fixed-points,
// continue). The other commands run in one process, and main() prints their errors.
#pragma once

#include <functional>
#include <string_view>

#include "mpi/mpi.hpp"

namespace superball::cli {

// Runs `body` on every rank of `world` and returns its status. Bad input (InputError: every
// rank read the same input and refused it alike) and a failure every rank met in step
// (RunError) are printed once, by rank 0, with status 2 and 1. Any other exception may have
// left the ranks out of step (the others would wait in a collective for ever): its rank
// prints it and ends them all (MPI_Abort, status 1).
int on_every_rank(std::string_view command, const mpi::Comm& world, const std::function<int()>& body);

}  // namespace superball::cli
