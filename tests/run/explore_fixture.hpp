// What the tests of run_explore (tests/run/mpi) and run_explore_threads (tests/run/threads)
// compare: a small job, its grid counted point by point by the scalar kernel (no MPI, no
// tiles, no files), and a result file read whole.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "run/progress.hpp"
#include "run/work_pool.hpp"

namespace superball::test_support {

inline Job job_of(const std::string& run = "tile_points = 64", int max_bounces = 1000)
{
    return parse_job("[model]\ne = 0.9\nalpha = 0.9\n[grid]\nxi = { min = 0.0, max = 1.0, n = 61 }\nU = -1.0\n"
                     "W = { min = -3.0, max = 3.0, n = 47 }\n[run]\nmax_bounces = " +
                         std::to_string(max_bounces) + "\n" + run + "\n",
                     "test job");
}

struct Data {
    std::vector<std::uint32_t> counts;
    std::vector<std::uint8_t> outcomes;
};

inline Data direct(const Job& job)
{
    const Grid grid(job);
    const Extent shape = grid.shape();
    const Box all{Extent(shape.size(), 0), shape};
    Starts starts;
    grid.starts(all, starts);
    Data d{std::vector<std::uint32_t>(starts.size()), std::vector<std::uint8_t>(starts.size())};
    count_each(starts.view(), ModelMatrices::of(job.model), job.max_bounces, d.counts, d.outcomes);
    return d;
}

// Counts the observer's calls (rank 0's, under MPI).
class Tally final : public RunObserver {
public:
    void started(const RunStart& s) override
    {
        ++starts;
        start = s;
    }
    void tiles_done(std::uint64_t t, std::uint64_t p) override
    {
        tiles += t;
        points += p;
    }
    void computed(double) override { ++computes; }
    void finishing() override { ++finishes; }

    RunStart start;
    int starts = 0, computes = 0, finishes = 0;
    std::uint64_t tiles = 0, points = 0;
};

inline const StopRequested never = [] { return false; };

inline Data read_result(const std::filesystem::path& path)
{
    const ResultReader reader(path);
    const ResultInfo& info = reader.info();
    EXPECT_EQ(info.kind, FileKind::result);
    const Box all{Extent(info.shape.size(), 0), info.shape};
    Data d{std::vector<std::uint32_t>(all.points()), std::vector<std::uint8_t>(all.points())};
    EXPECT_EQ(reader.read(all, d.counts, d.outcomes), 0u);
    return d;
}

}  // namespace superball::test_support
