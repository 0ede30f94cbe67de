// The compute cost of every tile of a job, from a real result of the same job at a lower
// resolution: the cost model the SMPI simulation (sim_run.cpp) replays.
//
//   scale_costs JOB.toml RANKS LOWRES.h5 NS_PER_POINT NS_PER_ITERATION US_PER_TILE OUT.bin
//
// A point of the job costs NS_PER_POINT + NS_PER_ITERATION x its wall bounces, taken
// from the low-resolution cell whose sample range holds it (nearest cell); a tile costs
// the sum over its points plus US_PER_TILE. The tiling is the one `superball explore`
// makes for RANKS ranks (default_tiling). OUT.bin: "SBCOST01", then u64 tiles, bytes
// written per point, points; tiles doubles (seconds); tiles u64 (points); tiles u64 (the
// tiles of a fresh run in the order explore hands them out, job/tiles.hpp handout_order;
// shared by all simulated ranks; with DONE.bin, only the tiles not in it). Prints one
// line: tiles, their points, the block granule, total compute, the costliest tile, the ideal
// time at RANKS ranks, the job's compression level and bytes per count. (How far the job's
// data compress is measured apart, at full resolution, by chunk_ratio.py: the sample's
// points lie 16-32 times farther apart than the job's along each axis, and its data
// compressed 3.9 times where the job's own chunks compress 20-70 times.)
#include <fmt/core.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/hdf5.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"

namespace {

using namespace superball;

struct LowRes {
    std::vector<std::uint64_t> shape;
    std::vector<double> cost;  // seconds per point of each low-resolution cell, row-major
};

LowRes read_lowres(const std::string& path, double ns_per_point, double ns_per_iteration)
{
    const h5::Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "open " + path);
    const h5::Id data = h5::dataset_id(H5Dopen2(file, "/wall_bounces", H5P_DEFAULT), "open /wall_bounces");
    LowRes low;
    for (const hsize_t n : h5::dataset_shape(data)) low.shape.push_back(n);
    std::uint64_t points = 1;
    for (const std::uint64_t n : low.shape) points *= n;
    std::vector<std::uint32_t> counts(points);
    h5::check(H5Dread(data, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, counts.data()), "read /wall_bounces");
    low.cost.resize(points);
    for (std::uint64_t i = 0; i < points; ++i) {
        low.cost[i] = (ns_per_point + ns_per_iteration * static_cast<double>(counts[i])) * 1e-9;
    }
    return low;
}

// For one axis: how many of the full-resolution samples [start, start + count) fall in
// each low-resolution cell (sample i of n sits in cell floor((i + 1/2) low / n)).
std::vector<std::pair<std::uint64_t, std::uint64_t>> overlap(std::uint64_t start, std::uint64_t count, std::uint64_t n,
                                                             std::uint64_t low)
{
    std::vector<std::pair<std::uint64_t, std::uint64_t>> cells;  // (cell, samples)
    for (std::uint64_t i = start; i < start + count; ++i) {
        const auto cell = std::min<std::uint64_t>(low - 1, ((2 * i + 1) * low) / (2 * n));
        if (!cells.empty() && cells.back().first == cell) {
            ++cells.back().second;
        } else {
            cells.push_back({cell, 1});
        }
    }
    return cells;
}

// Sum over the tile's points of their cell's cost: the overlaps multiply axis by axis.
double tile_cost(const Box& box, const Extent& shape, const LowRes& low)
{
    const std::size_t dims = shape.size();
    std::vector<std::vector<std::pair<std::uint64_t, std::uint64_t>>> axes;
    for (std::size_t d = 0; d < dims; ++d) axes.push_back(overlap(box.start[d], box.count[d], shape[d], low.shape[d]));
    double sum = 0;
    std::vector<std::size_t> at(dims, 0);
    for (;;) {
        std::uint64_t index = 0;
        double weight = 1;
        for (std::size_t d = 0; d < dims; ++d) {
            index = index * low.shape[d] + axes[d][at[d]].first;
            weight *= static_cast<double>(axes[d][at[d]].second);
        }
        sum += weight * low.cost[index];
        std::size_t d = dims;
        while (d-- > 0) {
            if (++at[d] < axes[d].size()) break;
            at[d] = 0;
        }
        if (d == static_cast<std::size_t>(-1)) return sum;
    }
}

template <class T>
void put(std::ofstream& out, const T& x)
{
    out.write(reinterpret_cast<const char*>(&x), sizeof x);
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc != 8 && argc != 9) {
        std::fprintf(stderr,
                     "usage: scale_costs JOB.toml RANKS LOWRES.h5 NS_PER_POINT NS_PER_ITERATION US_PER_TILE OUT.bin [DONE.bin]\n");
        return 2;
    }
    try {
        h5::silence_errors();
        const Job job = load_job(argv[1]);
        const int ranks = std::stoi(argv[2]);
        const LowRes low = read_lowres(argv[3], std::stod(argv[4]), std::stod(argv[5]));
        const double per_tile = std::stod(argv[6]) * 1e-6;
        const Tiling tiling = default_tiling(job, ranks);
        if (low.shape.size() != tiling.shape().size()) {
            throw std::runtime_error(fmt::format("{} has {} axes, the job {}", argv[3], low.shape.size(), tiling.shape().size()));
        }
        const std::uint64_t count_bytes = job.max_bounces > 65535 ? 4 : 2;  // /wall_bounces: uint16 or uint32
        std::vector<double> cost(tiling.tiles());
        std::vector<std::uint64_t> points(tiling.tiles());
        double total = 0;
        double worst = 0;
        for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
            const Box box = tiling.box(t);
            cost[t] = per_tile + tile_cost(box, tiling.shape(), low);
            points[t] = box.points();
            total += cost[t];
            worst = std::max(worst, cost[t]);
        }
        std::ofstream out(argv[7], std::ios::binary);
        out.write("SBCOST01", 8);
        put(out, tiling.tiles());
        put(out, count_bytes + 1);
        put(out, job.points());
        out.write(reinterpret_cast<const char*>(cost.data()), static_cast<std::streamsize>(cost.size() * sizeof(double)));
        out.write(reinterpret_cast<const char*>(points.data()), static_cast<std::streamsize>(points.size() * sizeof(std::uint64_t)));
        // Blocks are multiples of this many tiles where they can be, as run_explore asks
        // (uncompressed: one alignment unit of counts; compressed tiles go to rank 0: 1), and
        // the tiles are handed out in its order.
        const std::uint64_t granule =
            job.compression > 0 ? 1 : std::max<std::uint64_t>(1, job.alignment / (tiling.box(0).points() * count_bytes));
        // A resumed run (DONE.bin: the tiles its journal records done, u64 each, as sim_run
        // --lose-node-at writes them) hands out only the others, in the order a resume does.
        std::vector<bool> done(tiling.tiles(), false);
        if (argc == 9) {
            std::ifstream in(argv[8], std::ios::binary);
            if (!in) throw std::runtime_error(std::string("cannot read ") + argv[8]);
            std::uint64_t t = 0;
            while (in.read(reinterpret_cast<char*>(&t), sizeof t)) {
                if (t >= tiling.tiles()) throw std::runtime_error(fmt::format("{}: tile {} of {}", argv[8], t, tiling.tiles()));
                done[t] = true;
            }
        }
        std::vector<ListedTile> pending;
        for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
            if (!done[t]) pending.push_back(static_cast<ListedTile>(t));
        }
        for (const std::uint64_t t : handout_order(pending, granule, ranks >= interleave_ranks_default)) put(out, t);
        if (!out) throw std::runtime_error(std::string("cannot write ") + argv[7]);
        fmt::print("tiles={} tile_points={} granule={} compute_s={:.6g} costliest_tile_s={:.6g} ideal_s={:.6g} "
                   "compression={} count_bytes={} pending={}\n",
                   tiling.tiles(), tiling.box(0).points(), granule, total, worst, total / ranks, job.compression, count_bytes,
                   pending.size());
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "scale_costs: %s\n", e.what());
        return 1;
    }
}
