// The printer of a run's progress for people (a RunObserver, run/progress.hpp): a live
// line on a terminal, or a plain line every few seconds otherwise (Slurm logs). Used by
// the command line and the Python module.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>

#include "run/progress.hpp"

namespace superball {

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
