#include "final_result.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <system_error>

#include "hdf5.hpp"
#include "layout.hpp"
#include "xdmf.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {

std::vector<hsize_t> to_hsize(const Extent& e) { return {e.begin(), e.end()}; }

// Every rank opens and creates the files collectively; metadata are read by one rank and
// broadcast, and written collectively, so thousands of ranks do not each read the same
// object headers from the file system.
h5::Id parallel_access(const mpi::Comm& comm, std::uint64_t alignment)
{
    h5::Id fapl = h5::file_access(alignment);
    // Collective writes through a few aggregators in stripe-sized pieces (ROMIO, Open MPI's
    // choice on Lustre; OMPIO's two-phase writer elsewhere, see mpi/mpi.hpp): compressed chunks are a few KiB each, and ranks writing
    // them one by one into shared stripes would take each other's locks. No data sieving
    // (read-modify-write of the holes between chunks). Implementations ignore hints they
    // do not know. The aggregators' buffer: one stripe (ROMIO's default is 16 MiB), so
    // each write is a whole stripe: a round of this pass is at most 8 MiB of raw data per
    // rank, much less compressed, and OMPIO's two-phase writer (mpi/mpi.hpp) holds the
    // buffer whole: 16 MiB raised the peak memory of a 16384^2 run at -n 2 from 67 to
    // 71 MiB per rank (4096^2: 62), 4 MiB to 69; the write calls were the same.
    mpi::Info hints;
    hints.set("romio_cb_write", "enable");
    hints.set("romio_ds_write", "disable");
    const std::uint64_t stripe = std::max<std::uint64_t>(alignment, std::uint64_t{1} << 20);
    hints.set("cb_buffer_size", std::to_string(stripe));
    hints.set("striping_unit", std::to_string(stripe));
    h5::check(H5Pset_fapl_mpio(fapl, comm.get(), hints.get()), "H5Pset_fapl_mpio");
    h5::check(H5Pset_all_coll_metadata_ops(fapl, true), "H5Pset_all_coll_metadata_ops");
    h5::check(H5Pset_coll_metadata_write(fapl, true), "H5Pset_coll_metadata_write");
    return fapl;
}

h5::Id create_data(hid_t file, const char* name, hid_t type, const Extent& shape, const Extent& chunk, int level)
{
    const h5::Id space = h5::simple_space(to_hsize(shape));
    const auto c = to_hsize(chunk);
    const h5::Id dcpl = h5::plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
    h5::check(H5Pset_chunk(dcpl, static_cast<int>(c.size()), c.data()), "H5Pset_chunk");
    if (level > 0) {
        // Shuffle groups the bytes of the counts by significance (the high bytes are mostly
        // zero), then deflate: every HDF5 reads it without plugins (h5py, netCDF-4, ParaView).
        h5::check(H5Pset_shuffle(dcpl), "H5Pset_shuffle");
        h5::check(H5Pset_deflate(dcpl, static_cast<unsigned>(level)), "H5Pset_deflate");
        // Chunks take space as they are written, compressed: nothing is allocated or
        // filled for them beforehand.
        h5::check(H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_INCR), "H5Pset_alloc_time");
    } else {
        h5::check(H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY), "H5Pset_alloc_time");
    }
    h5::check(H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER), "H5Pset_fill_time");
    return h5::dataset_id(H5Dcreate2(file, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), name);
}

// Chunks [first, last) of `chunks` as boxes of at most `most` consecutive chunks that lie
// in one row of chunks (the same chunk along every axis but the last), so each is a box of
// the grid: HDF5 copies a box chunk by chunk, while a union of boxes against a flat memory
// space makes it map every element (measured 10 times slower).
std::vector<Box> boxes_of(const Tiling& chunks, std::uint64_t first, std::uint64_t last, std::uint64_t most)
{
    std::vector<Box> boxes;
    const std::size_t d = chunks.shape().size();
    const std::uint64_t per_row = (chunks.shape()[d - 1] + chunks.tile_shape()[d - 1] - 1) / chunks.tile_shape()[d - 1];
    for (std::uint64_t c = first; c < last;) {
        const std::uint64_t row_end = (c / per_row + 1) * per_row;
        const std::uint64_t end = std::min({last, row_end, c + most});
        Box b = chunks.box(c);
        const Box tail = chunks.box(end - 1);
        b.count[d - 1] = tail.start[d - 1] + tail.count[d - 1] - b.start[d - 1];
        boxes.push_back(std::move(b));
        c = end;
    }
    return boxes;
}

std::uint64_t size_of(const fs::path& p)
{
    std::error_code ec;
    const auto n = fs::file_size(p, ec);
    return ec ? 0 : n;
}

}  // namespace

FinishReport write_result(const fs::path& partial, const fs::path& output, const Job& job, const Grid& grid,
                          const mpi::Comm& comm, const RunFigures& run)
{
    const auto started = std::chrono::steady_clock::now();
    const fs::path tmp = layout::finishing_path(output);
    const Extent shape = grid.shape();
    const Tiling chunks(shape, default_tile_shape(shape, result_chunk_points));
    const hid_t counts_type = count_type(job);
    const hid_t counts_memory = H5Tget_size(counts_type) == 2 ? H5T_NATIVE_UINT16 : H5T_NATIVE_UINT32;
    const std::size_t count_bytes = H5Tget_size(counts_type);
    std::uint64_t chunk_points = 1;
    for (const std::uint64_t c : chunks.tile_shape()) chunk_points *= c;
    {
        const h5::Id in = h5::open_file(partial, false, parallel_access(comm, 0));
        const h5::Id out = h5::create_file(tmp, parallel_access(comm, job.alignment));
        const std::vector<h5::Id> axes = write_metadata(out, job, grid, layout::kind_result, run, comm.is_root());
        const h5::Id counts = create_data(out, layout::wall_bounces, counts_type, shape, chunks.tile_shape(), job.compression);
        const h5::Id outcomes = create_data(out, layout::outcome, H5T_STD_U8LE, shape, chunks.tile_shape(), job.compression);
        describe_data(counts, outcomes, job, axes);
        const h5::Id counts_in = h5::open_dataset(in, layout::wall_bounces);
        const h5::Id outcomes_in = h5::open_dataset(in, layout::outcome);

        // This rank's chunks: a contiguous share of them in chunk order, taken a bounded
        // number at a time (8 MiB of data); every rank makes as many collective writes as
        // the rank with the most, selecting nothing once its share is done.
        const auto ranks = static_cast<std::uint64_t>(comm.size());
        const auto share = [&](std::uint64_t r, std::uint64_t most) {
            return boxes_of(chunks, chunks.tiles() * r / ranks, chunks.tiles() * (r + 1) / ranks, most);
        };
        const std::uint64_t most = std::max<std::uint64_t>(1, (std::uint64_t{8} << 20) / (chunk_points * (count_bytes + 1)));
        const std::vector<Box> mine = share(static_cast<std::uint64_t>(comm.rank()), most);
        std::size_t rounds = 0;
        for (std::uint64_t r = 0; r < ranks; ++r) rounds = std::max(rounds, share(r, most).size());
        const h5::Id collective = h5::plist_id(H5Pcreate(H5P_DATASET_XFER), "H5Pcreate");
        h5::check(H5Pset_dxpl_mpio(collective, H5FD_MPIO_COLLECTIVE), "H5Pset_dxpl_mpio");
        std::vector<std::byte> buf_counts, buf_outcomes;
        for (std::size_t round = 0; round < rounds; ++round) {
            const h5::Id file_space = h5::space_id(H5Dget_space(counts), "H5Dget_space");
            h5::Id memory;
            if (round < mine.size()) {
                const Box& b = mine[round];
                h5::select_box(file_space, to_hsize(b.start), to_hsize(b.count));
                memory = h5::simple_space(to_hsize(b.count));
                buf_counts.resize(b.points() * count_bytes);
                buf_outcomes.resize(b.points());
                h5::check(H5Dread(counts_in, counts_memory, memory, file_space, H5P_DEFAULT, buf_counts.data()),
                          "read /wall_bounces of " + partial.string());
                h5::check(H5Dread(outcomes_in, H5T_NATIVE_UINT8, memory, file_space, H5P_DEFAULT, buf_outcomes.data()),
                          "read /outcome of " + partial.string());
            } else {
                h5::check(H5Sselect_none(file_space), "H5Sselect_none");
                memory = h5::simple_space({1});
                h5::check(H5Sselect_none(memory), "H5Sselect_none");
                buf_counts.resize(count_bytes);
                buf_outcomes.resize(1);
            }
            h5::check(H5Dwrite(counts, counts_memory, memory, file_space, collective, buf_counts.data()),
                      "write /wall_bounces of " + tmp.string());
            h5::check(H5Dwrite(outcomes, H5T_NATIVE_UINT8, memory, file_space, collective, buf_outcomes.data()),
                      "write /outcome of " + tmp.string());
        }
    }  // every file closed, collectively
    FinishReport report;
    std::int64_t failed = 0;
    std::string why;
    if (comm.is_root()) {
        // The result takes its name only now, whole; then the partial file goes.
        std::error_code ec;
        fs::rename(tmp, output, ec);
        if (ec) {
            failed = 1;
            why = fmt::format("renaming {} to {} failed ({})", tmp.string(), output.string(), ec.message());
        } else {
            fs::remove(partial, ec);
            report.file_bytes = size_of(output);
            // The result is complete whatever happens to its sidecar: a failure here is a
            // note, and must not leave the other ranks waiting below.
            try {
                const fs::path xmf = write_xdmf(output);
                report.sidecar_note = xmf.empty() ? "no XDMF sidecar: " + xdmf_unsupported(output) : "sidecar: " + xmf.string();
            } catch (const std::exception& e) {
                report.sidecar_note = std::string("no XDMF sidecar: writing it failed (") + e.what() + ")";
            }
        }
    }
    if (comm.broadcast(failed) != 0) {
        comm.broadcast(why);
        throw mpi::CollectiveError(why);
    }
    report.raw_bytes = count_bytes + 1;
    for (const std::uint64_t n : shape) report.raw_bytes *= n;
    report.file_bytes = static_cast<std::uint64_t>(comm.broadcast(static_cast<std::int64_t>(report.file_bytes)));
    comm.broadcast(report.sidecar_note);
    report.seconds = comm.broadcast(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    return report;
}

}  // namespace superball
