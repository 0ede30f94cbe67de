// Progress of a run as rank 0 sees it: an observer interface. The printer for people is
// the front ends' (cli/terminal_progress.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace superball {

// What a run is about to do (rank 0's observer is told).
struct RunStart {
    std::filesystem::path output;
    std::string note;               // what was decided about the output, for the user (may be empty)
    int ranks = 1;
    std::uint64_t grid_points = 0;
    std::uint64_t tiles = 0;
    std::uint64_t tile_points = 0;  // of a full tile
    std::uint64_t tiles_done = 0;   // by earlier runs (resume)
    std::uint64_t points_done = 0;
};

// Rank 0's view of a run. Calls come one at a time: from rank 0's thread in a run over MPI
// ranks (run_explore), from any of the counting threads in a run on threads
// (run_explore_threads), so an observer keeps no thread-local state.
class RunObserver {
public:
    virtual ~RunObserver() = default;
    virtual void started(const RunStart&) {}
    // `tiles` more tiles of `points` points in all are done.
    virtual void tiles_done(std::uint64_t /*tiles*/, std::uint64_t /*points*/) {}
    // The compute phase is over (before the result is written).
    virtual void computed(double /*seconds*/) {}
    // Every tile is done: the partial file is being made the result.
    virtual void finishing() {}
};

}  // namespace superball
