// The schedule's own cost per tile: run_schedule over TILES tiles whose work is a busy
// wait of WORK_US microseconds (split in two by a Serve call, as the counter calls it for a
// 1024-point tile; flush returns the tiles), REPS times. Prints the median time and the
// overhead per tile: (time x ranks - tiles x WORK_US) / tiles, the core time the schedule
// adds to each tile (with WORK_US = 17, about a 1024-point tile of the trivial benchmark
// grid).
//
//   mpiexec -n 2 build/release/tests/scale/bench_schedule [TILES] [REPS] [WORK_US]
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "mpi/mpi.hpp"
#include "run/schedule.hpp"

namespace {

using namespace superball;

void spin(double seconds)
{
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
    }
}

class Spin final : public TileWork {
public:
    explicit Spin(double seconds) : seconds_(seconds) {}
    void compute(std::uint64_t tile, const Serve& serve) override
    {
        spin(seconds_ / 2);
        if (serve) serve();
        spin(seconds_ / 2);
        if (serve) serve();
        done_.push_back({tile, tile});
    }
    std::vector<TileReport> flush() override
    {
        std::vector<TileReport> out;
        out.swap(done_);
        return out;
    }

private:
    double seconds_;
    std::vector<TileReport> done_;
};

}  // namespace

int main(int argc, char** argv)
{
    const mpi::Environment env;
    const mpi::Comm world = mpi::Comm::world();
    const std::uint64_t tiles = argc > 1 ? std::stoull(argv[1]) : 65536;
    const int reps = argc > 2 ? std::stoi(argv[2]) : 5;
    const double work = (argc > 3 ? std::stod(argv[3]) : 17) * 1e-6;
    std::vector<ListedTile> pending(tiles);
    for (std::uint64_t t = 0; t < tiles; ++t) pending[t] = t;
    std::vector<double> times;
    std::uint64_t requests = 0;
    for (int r = 0; r < reps; ++r) {
        Spin spinning(work);
        world.barrier();
        const double start = MPI_Wtime();
        const ScheduleResult res = run_schedule(world, pending, spinning, [](std::span<const TileReport>, int) {}, [] { return false; });
        times.push_back(world.max(MPI_Wtime() - start));
        requests = res.stats.requests_in;
    }
    std::sort(times.begin(), times.end());
    if (world.is_root()) {
        const double median = times[times.size() / 2];
        const double overhead = (median * world.size() - static_cast<double>(tiles) * work) / static_cast<double>(tiles);
        std::printf("ranks=%d tiles=%llu work_us=%.1f median_s=%.6f overhead_us_per_tile=%.3f root_requests=%llu\n",
                    world.size(), static_cast<unsigned long long>(tiles), work * 1e6, median, overhead * 1e6,
                    static_cast<unsigned long long>(requests));
    }
    return 0;
}
