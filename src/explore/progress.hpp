// Progress of a run as rank 0 sees it: a live line on a terminal, a plain line every
// few seconds otherwise (Slurm logs), and the summary at the end.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace superball {

class Progress {
public:
    // total_*: the whole grid; already_*: done by earlier runs (resume).
    // quiet: count, but print nothing.
    Progress(std::FILE* out, bool quiet, std::uint64_t total_tiles, std::uint64_t total_points, std::uint64_t already_tiles,
             std::uint64_t already_points);

    // A tile of `points` points finished.
    void tile_done(std::uint64_t points);
    // Stops the clock and ends the live line.
    void finish();

    // Seconds from construction to finish() (or to now, before it).
    double seconds() const;
    std::uint64_t points_this_run() const { return points_run_; }

private:
    void report(bool final);

    using Clock = std::chrono::steady_clock;
    std::FILE* out_;
    bool quiet_;
    bool live_;
    std::uint64_t total_tiles_, total_points_;
    std::uint64_t tiles_done_, points_done_, points_run_ = 0;
    Clock::time_point start_ = Clock::now();
    Clock::time_point last_report_ = start_;
    Clock::time_point stop_{};
    bool stopped_ = false;
};

}  // namespace superball
