// Dynamic schedule of tiles over MPI ranks.
//
// The cost of a point varies by orders of magnitude across a grid (one bounce near the
// edges, up to max_bounces near self-similar motions), so tiles are handed out on
// demand rather than split statically, in blocks of consecutive tiles whose size shrinks
// as the work runs out (guided self-scheduling): the scheduler answers O(P log(N/P))
// requests for N tiles on P ranks, not N, and the last blocks are single tiles so the
// ranks finish together. Results never depend on the schedule: every tile is computed
// the same way wherever it runs.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "job/tiles.hpp"
#include "mpi/mpi.hpp"

namespace superball {

// The rank that schedules calls `serve` from inside its own work every few hundred
// points, so that waiting ranks get their next block promptly; elsewhere (and when no
// other rank waits: a run on one rank) it is empty.
using Serve = std::function<void()>;

// What a rank does with the tiles it is given.
class TileWork {
public:
    virtual ~TileWork() = default;
    // Counts tile `tile` and hands its data to the writer, which may write it now or
    // keep it for a larger write.
    virtual void compute(std::uint64_t tile, const Serve& serve) = 0;
    // Writes every tile computed so far that is not yet written, and returns the reports
    // of the tiles written since the last call, in the order they were computed. Only a
    // tile returned here may be recorded done: its data are in the file.
    virtual std::vector<TileReport> flush() = 0;
};

// Called on rank 0 for finished tiles (written, see TileWork::flush), whichever rank
// computed them.
using TilesDone = std::function<void(std::span<const TileReport> tiles, int rank)>;
// Polled on every rank between tiles: true on any rank stops the handing out of work
// (the run is interrupted; the tile being computed is finished, written and reported).
using StopRequested = std::function<bool()>;

struct ScheduleSettings {
    // A rank with finished tiles reports them (flushing its writes) at least this often,
    // so the resume journal lags the work by no more than that.
    double report_seconds = 1.0;
    // Blocks are multiples of this many tiles where they can be (a stripe of the file
    // system's alignment, so that two ranks' writes do not share one).
    std::uint64_t granule = 1;
};

struct ScheduleResult {
    bool interrupted = false;  // on every rank: tiles were left undone on purpose
};

// Collective over `comm`. `pending` (identical on every rank): the tiles to compute, in
// the order they are handed out; consecutive entries form the blocks.
ScheduleResult run_schedule(const mpi::Comm& comm, std::span<const std::uint64_t> pending, TileWork& work,
                            const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings = {});

}  // namespace superball
