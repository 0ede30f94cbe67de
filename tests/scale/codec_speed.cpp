// How fast a rank compresses the tiles of a job (the scaling simulation's compression
// speed, tests/scale/chunk_ratio.py): reads a compressed result written by explore (its
// chunks are the job's tiles), cuts its data into those chunks as explore cuts its tiles,
// and encodes each one as a rank does (io/chunk_codec.hpp, at LEVEL), with a fresh encoder
// per pass as a rank starts with one; the fastest of 3 passes. The speed depends on the
// data (flat regions compress several times faster than the fine structure of a basin
// boundary), so it is measured on the job's own data at full resolution, not on one
// benchmark. Prints "raw_bytes=R seconds=S": raw bytes (counts as stored plus outcomes)
// and the seconds of the fastest pass.
//
//   codec_speed RESULT.h5 LEVEL
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "io/chunk_codec.hpp"
#include "io/hdf5.hpp"
#include "io/partial_file.hpp"
#include "job/tiles.hpp"

using namespace superball;

namespace {

template <class T>
std::vector<T> read_all(hid_t file, const char* name, hid_t type, std::vector<std::uint64_t>& shape, std::vector<std::uint64_t>& chunk)
{
    const h5::Id data = h5::dataset_id(H5Dopen2(file, name, H5P_DEFAULT), name);
    shape.clear();
    for (const hsize_t n : h5::dataset_shape(data)) shape.push_back(n);
    const h5::Id plist = h5::plist_id(H5Dget_create_plist(data), "the creation properties of a dataset");
    std::vector<hsize_t> dims(shape.size());
    if (H5Pget_chunk(plist, static_cast<int>(dims.size()), dims.data()) != static_cast<int>(dims.size())) {
        throw std::runtime_error(std::string(name) + " is not chunked");
    }
    chunk.assign(dims.begin(), dims.end());
    std::uint64_t points = 1;
    for (const std::uint64_t n : shape) points *= n;
    std::vector<T> values(points);
    h5::check(H5Dread(data, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name);
    return values;
}

}  // namespace

int main(int argc, char** argv)
{
    try {
        if (argc != 3) throw std::runtime_error("usage: codec_speed RESULT.h5 LEVEL");
        const int level = std::stoi(argv[2]);
        const h5::Id file(H5Fopen(argv[1], H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, std::string("open ") + argv[1]);
        std::vector<std::uint64_t> shape, chunk, oshape, ochunk;
        const auto counts = read_all<std::uint32_t>(file, "/wall_bounces", H5T_NATIVE_UINT32, shape, chunk);
        const auto outcomes = read_all<std::uint8_t>(file, "/outcome", H5T_NATIVE_UINT8, oshape, ochunk);
        const h5::Id data = h5::dataset_id(H5Dopen2(file, "/wall_bounces", H5P_DEFAULT), "/wall_bounces");
        const h5::Id type = h5::type_id(H5Dget_type(data), "the type of /wall_bounces");
        const std::size_t count_bytes = H5Tget_size(type);
        const Tiling tiling(shape, chunk);
        std::vector<std::uint32_t> c, cc;
        std::vector<std::uint8_t> o, oc;
        std::vector<std::byte> out;
        double best = 1e300;
        for (int pass = 0; pass < 3; ++pass) {
            ChunkEncoder encoder(level);
            double seconds = 0;
            for (std::uint64_t t = 0; t < tiling.tiles(); ++t) {
                const Box b = tiling.box(t);
                c.resize(b.points());
                o.resize(b.points());
                const Extent origin(shape.size(), 0);
                copy_box(b, reinterpret_cast<const std::byte*>(counts.data()), origin, shape, reinterpret_cast<std::byte*>(c.data()),
                         b.start, b.count, 4);
                copy_box(b, reinterpret_cast<const std::byte*>(outcomes.data()), origin, shape,
                         reinterpret_cast<std::byte*>(o.data()), b.start, b.count, 1);
                // Timed as a rank's work on a counted tile: the layout of its chunk and the
                // two encodings (the copy out of the whole array above is this tool's own).
                const auto start = std::chrono::steady_clock::now();
                out.clear();
                encoder.counts(in_chunk_layout<std::uint32_t>(tiling, t, c, cc), count_bytes, out);
                encoder.outcomes(in_chunk_layout<std::uint8_t>(tiling, t, o, oc), out);
                seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
            best = std::min(best, seconds);
        }
        fmt::print("raw_bytes={} seconds={:.6g}\n", counts.size() * (count_bytes + 1), best);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "codec_speed: %s\n", e.what());
        return 1;
    }
}
