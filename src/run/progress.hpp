// Progress of a run as rank 0 sees it: an observer interface, and its implementation for
// people, a live line on a terminal or a plain line every few seconds otherwise (Slurm
// logs).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
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

// Rank 0's view of a run; every call comes from rank 0's thread.
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

// Prints the plan's note and the start line, then tiles done, points/s, elapsed time and
// ETA: redrawn every 200 ms on a terminal, a new line every 10 s otherwise.
class TerminalProgress : public RunObserver {
public:
    // quiet: print nothing.
    TerminalProgress(std::FILE* out, bool quiet);

    void started(const RunStart& s) override;
    void tiles_done(std::uint64_t tiles, std::uint64_t points) override;
    void computed(double seconds) override;
    void finishing() override;

private:
    void report(bool final);
    double seconds() const;

    using Clock = std::chrono::steady_clock;
    std::FILE* out_;
    bool quiet_;
    bool live_;
    std::uint64_t total_tiles_ = 0, total_points_ = 0;
    std::uint64_t tiles_done_ = 0, points_done_ = 0, points_run_ = 0;
    Clock::time_point start_ = Clock::now();
    Clock::time_point last_report_ = start_;
    double final_seconds_ = -1;
};

}  // namespace superball
