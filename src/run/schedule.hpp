// Dynamic master-worker schedule of tiles over MPI ranks.
//
// The cost of a point varies by orders of magnitude across a grid (one bounce near the
// edges, up to max_bounces near self-similar motions), so tiles are handed out on
// demand rather than split statically. Rank 0 hands them out and computes tiles too,
// answering requests between blocks of points, so no core idles on a small machine.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>

#include "mpi/mpi.hpp"

namespace superball {

// Rank 0's work calls `serve` every few hundred points so that waiting ranks get their
// next tile promptly; on other ranks `serve` does nothing.
using Serve = std::function<void()>;
using TileWork = std::function<void(std::uint64_t tile, const Serve& serve)>;
// Called on rank 0 once per finished tile, whichever rank computed it.
using TileDone = std::function<void(std::uint64_t tile, int rank)>;
// Polled on every rank between tiles: true on any rank stops the handing out of tiles
// (the run is interrupted; tiles being computed are finished).
using StopRequested = std::function<bool()>;

struct ScheduleResult {
    bool interrupted = false;  // on every rank: tiles were left undone on purpose
};

// Collective over `comm`. `pending` (read on rank 0 only): the tiles to compute, in the
// order they are handed out.
ScheduleResult run_schedule(const mpi::Comm& comm, std::deque<std::uint64_t> pending, const TileWork& work,
                            const TileDone& done, const StopRequested& stop);

}  // namespace superball
