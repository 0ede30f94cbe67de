#include "final_result.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <map>
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

// A box of the result and the first of the chunks it covers (chunk order).
struct ChunkBox {
    std::uint64_t first_chunk = 0;
    Box box;
};

// Chunks [first, last) of `chunks` as boxes of at most `most` consecutive chunks that lie
// in one row of chunks (the same chunk along every axis but the last), so each is a box of
// the grid: HDF5 copies a box chunk by chunk, while a union of boxes against a flat memory
// space makes it map every element (measured 10 times slower).
std::vector<ChunkBox> boxes_of(const Tiling& chunks, std::uint64_t first, std::uint64_t last, std::uint64_t most)
{
    std::vector<ChunkBox> boxes;
    const std::size_t d = chunks.shape().size();
    const std::uint64_t per_row = (chunks.shape()[d - 1] + chunks.tile_shape()[d - 1] - 1) / chunks.tile_shape()[d - 1];
    for (std::uint64_t c = first; c < last;) {
        const std::uint64_t row_end = (c / per_row + 1) * per_row;
        const std::uint64_t end = std::min({last, row_end, c + most});
        Box b = chunks.box(c);
        const Box tail = chunks.box(end - 1);
        b.count[d - 1] = tail.start[d - 1] + tail.count[d - 1] - b.start[d - 1];
        boxes.push_back({c, std::move(b)});
        c = end;
    }
    return boxes;
}

// ------------------------------------------------------------------ the share from memory

// The common part of two boxes (empty counts if none).
Box intersect(const Box& a, const Box& b)
{
    Box r{Extent(a.start.size()), Extent(a.start.size())};
    for (std::size_t d = 0; d < a.start.size(); ++d) {
        const std::uint64_t lo = std::max(a.start[d], b.start[d]);
        const std::uint64_t hi = std::min(a.start[d] + a.count[d], b.start[d] + b.count[d]);
        r.start[d] = lo;
        r.count[d] = hi > lo ? hi - lo : 0;
    }
    return r;
}

// Copies the values of box `part` (grid coordinates) of `bytes` bytes each from `src`, a
// row-major array over the box at `src_start` of shape `src_shape`, into `dst`, likewise;
// both boxes hold `part`.
void copy_box(const Box& part, const std::byte* src, const Extent& src_start, const Extent& src_shape, std::byte* dst,
              const Extent& dst_start, const Extent& dst_shape, std::size_t bytes)
{
    const std::size_t dims = part.start.size();
    const std::size_t row = part.count[dims - 1] * bytes;
    if (part.points() == 0) return;
    Extent at(dims, 0);  // index within part of the current row (last axis 0)
    for (;;) {
        std::uint64_t s = 0, t = 0;
        for (std::size_t d = 0; d < dims; ++d) {
            s = s * src_shape[d] + (part.start[d] + at[d] - src_start[d]);
            t = t * dst_shape[d] + (part.start[d] + at[d] - dst_start[d]);
        }
        std::memcpy(dst + t * bytes, src + s * bytes, row);
        std::size_t d = dims - 1;
        while (d-- > 0) {
            if (++at[d] < part.count[d]) break;
            at[d] = 0;
        }
        if (d == static_cast<std::size_t>(-1)) return;
    }
}

// Calls f(number) for every tile or chunk of `tiling` meeting box `b`, in ascending order.
template <class F>
void for_each_meeting(const Tiling& tiling, const Box& b, F&& f)
{
    const std::size_t dims = b.start.size();
    Extent lo(dims), hi(dims), per(dims), at(dims);
    for (std::size_t d = 0; d < dims; ++d) {
        const std::uint64_t size = tiling.tile_shape()[d];
        lo[d] = b.start[d] / size;
        hi[d] = (b.start[d] + b.count[d] - 1) / size;
        per[d] = (tiling.shape()[d] + size - 1) / size;
        at[d] = lo[d];
    }
    for (;;) {
        std::uint64_t t = 0;
        for (std::size_t d = 0; d < dims; ++d) t = t * per[d] + at[d];
        f(t);
        std::size_t d = dims;
        while (d-- > 0) {
            if (++at[d] <= hi[d]) break;
            at[d] = lo[d];
        }
        if (d == static_cast<std::size_t>(-1)) return;
    }
}

// One box of this rank's share, whole in memory.
struct BoxData {
    std::vector<std::byte> counts, outcomes;
};

// This rank's share of the result (its boxes `mine`, of shares `boxes_of_rank` among the
// ranks), from the tiles every rank kept and, for boxes meeting a tile nobody kept, from
// the partial file. Collective.
std::vector<BoxData> gather_share(const mpi::Comm& comm, const Retained& retained, const Tiling& chunks,
                                  const std::function<const std::vector<ChunkBox>&(int)>& boxes_of_rank,
                                  std::size_t count_bytes, const std::function<void(const Box&, BoxData&)>& read)
{
    const Tiling& tiling = *retained.tiling;
    const int me = comm.rank();
    const auto ranks = static_cast<std::uint64_t>(comm.size());
    const Extent& tile_shape = tiling.tile_shape();
    // Which rank keeps each tile (-1: none; read from the file).
    std::vector<std::int32_t> owner(tiling.tiles(), -1);
    const std::vector<std::uint64_t> kept = retained.tiles ? retained.tiles->tiles() : std::vector<std::uint64_t>{};
    for (const std::uint64_t t : kept) owner[t] = me;
    owner = comm.max(owner);

    // A kept tile's chunk of counts, its chunk of outcomes after it.
    const auto chunk_of = [&](std::uint64_t t) { return retained.tiles->find(t); };
    const std::uint64_t counts_chunk = retained.tiles ? retained.tiles->counts_chunk() : 0;

    // This rank's boxes: from the file where a tile nobody kept meets them, then the tiles
    // kept here; what the other ranks send is counted.
    const std::vector<ChunkBox>& mine = boxes_of_rank(me);
    std::vector<BoxData> data(mine.size());
    std::vector<std::uint64_t> recv_counts(ranks, 0);
    for (std::size_t i = 0; i < mine.size(); ++i) {
        const Box& b = mine[i].box;
        data[i].counts.resize(b.points() * count_bytes);
        data[i].outcomes.resize(b.points());
        bool from_file = false;
        for_each_meeting(tiling, b, [&](std::uint64_t t) { from_file = from_file || owner[t] < 0; });
        if (from_file) read(b, data[i]);
        for_each_meeting(tiling, b, [&](std::uint64_t t) {
            const Box part = intersect(tiling.box(t), b);
            if (owner[t] == me) {
                const Box tb = tiling.box(t);
                const std::byte* chunk = chunk_of(t);
                copy_box(part, chunk, tb.start, tile_shape, data[i].counts.data(), b.start, b.count, count_bytes);
                copy_box(part, chunk + counts_chunk, tb.start, tile_shape, data[i].outcomes.data(), b.start, b.count, 1);
            } else if (owner[t] >= 0) {
                recv_counts[static_cast<std::size_t>(owner[t])] += part.points() * (count_bytes + 1);
            }
        });
    }

    // What this rank sends: the parts of its tiles that meet other ranks' boxes, for each
    // rank in the order it unpacks them (its boxes in order, tiles ascending in each).
    struct Part {
        std::size_t box;
        std::uint64_t tile;
        Box part;
    };
    std::vector<std::vector<Part>> to(ranks);
    const std::uint64_t n_chunks = chunks.tiles();
    for (const std::uint64_t t : kept) {
        const Box tb = tiling.box(t);
        std::vector<std::pair<std::uint64_t, std::size_t>> seen;  // (rank, box) this tile went to
        for_each_meeting(chunks, tb, [&](std::uint64_t c) {
            // Shares are contiguous: rank r holds chunks [n r / R, n (r + 1) / R).
            const std::uint64_t r = ((c + 1) * ranks - 1) / n_chunks;
            if (r == static_cast<std::uint64_t>(me)) return;
            const std::vector<ChunkBox>& theirs = boxes_of_rank(static_cast<int>(r));
            const auto it = std::upper_bound(theirs.begin(), theirs.end(), c,
                                             [](std::uint64_t x, const ChunkBox& cb) { return x < cb.first_chunk; });
            const auto k = static_cast<std::size_t>(it - theirs.begin() - 1);
            if (std::find(seen.begin(), seen.end(), std::pair{r, k}) != seen.end()) return;
            seen.push_back({r, k});
            to[r].push_back({k, t, intersect(tb, theirs[k].box)});
        });
    }
    std::vector<std::uint64_t> send_counts(ranks, 0);
    std::uint64_t total = 0;
    for (std::uint64_t r = 0; r < ranks; ++r) {
        std::sort(to[r].begin(), to[r].end(),
                  [](const Part& a, const Part& b) { return a.box != b.box ? a.box < b.box : a.tile < b.tile; });
        for (const Part& p : to[r]) send_counts[r] += p.part.points() * (count_bytes + 1);
        total += send_counts[r];
    }
    std::vector<std::byte> send(total);
    std::byte* out = send.data();
    for (std::uint64_t r = 0; r < ranks; ++r) {
        for (const Part& p : to[r]) {
            const Box tb = tiling.box(p.tile);
            const std::byte* chunk = chunk_of(p.tile);
            copy_box(p.part, chunk, tb.start, tile_shape, out, p.part.start, p.part.count, count_bytes);
            out += p.part.points() * count_bytes;
            copy_box(p.part, chunk + counts_chunk, tb.start, tile_shape, out, p.part.start, p.part.count, 1);
            out += p.part.points();
        }
    }
    const std::vector<std::byte> received = comm.alltoallv(send, send_counts, recv_counts);

    // Unpacked in the order the senders packed.
    std::vector<std::uint64_t> cursor(ranks, 0);
    for (std::uint64_t r = 1; r < ranks; ++r) cursor[r] = cursor[r - 1] + recv_counts[r - 1];
    for (std::size_t i = 0; i < mine.size(); ++i) {
        const Box& b = mine[i].box;
        for_each_meeting(tiling, b, [&](std::uint64_t t) {
            const std::int32_t o = owner[t];
            if (o < 0 || o == me) return;
            const Box part = intersect(tiling.box(t), b);
            std::uint64_t& at = cursor[static_cast<std::size_t>(o)];
            copy_box(part, received.data() + at, part.start, part.count, data[i].counts.data(), b.start, b.count, count_bytes);
            at += part.points() * count_bytes;
            copy_box(part, received.data() + at, part.start, part.count, data[i].outcomes.data(), b.start, b.count, 1);
            at += part.points();
        });
    }
    return data;
}

std::uint64_t size_of(const fs::path& p)
{
    std::error_code ec;
    const auto n = fs::file_size(p, ec);
    return ec ? 0 : n;
}

}  // namespace

Tiling result_chunks(const Extent& shape) { return Tiling(shape, default_tile_shape(shape, result_chunk_points)); }

FinishReport write_result(const fs::path& partial, const fs::path& output, const Job& job, const Grid& grid,
                          const mpi::Comm& comm, const RunFigures& run, const Retained& retained)
{
    const auto started = std::chrono::steady_clock::now();
    const fs::path tmp = layout::finishing_path(output);
    const Extent shape = grid.shape();
    const Tiling chunks = result_chunks(shape);
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
        const std::uint64_t most = std::max<std::uint64_t>(1, (std::uint64_t{8} << 20) / (chunk_points * (count_bytes + 1)));
        std::map<int, std::vector<ChunkBox>> shares;  // by rank, each computed once
        const auto share = [&](int r) -> const std::vector<ChunkBox>& {
            auto it = shares.find(r);
            if (it == shares.end()) {
                const auto q = static_cast<std::uint64_t>(r);
                it = shares.emplace(r, boxes_of(chunks, chunks.tiles() * q / ranks, chunks.tiles() * (q + 1) / ranks, most)).first;
            }
            return it->second;
        };
        const std::vector<ChunkBox>& mine = share(comm.rank());
        std::size_t rounds = 0;
        for (int r = 0; r < comm.size(); ++r) rounds = std::max(rounds, share(r).size());
        const auto read = [&](const Box& b, BoxData& d) {
            const h5::Id file_space = h5::space_id(H5Dget_space(counts_in), "H5Dget_space");
            h5::select_box(file_space, to_hsize(b.start), to_hsize(b.count));
            const h5::Id memory = h5::simple_space(to_hsize(b.count));
            h5::check(H5Dread(counts_in, counts_memory, memory, file_space, H5P_DEFAULT, d.counts.data()),
                      "read /wall_bounces of " + partial.string());
            h5::check(H5Dread(outcomes_in, H5T_NATIVE_UINT8, memory, file_space, H5P_DEFAULT, d.outcomes.data()),
                      "read /outcome of " + partial.string());
        };
        // Kept tiles anywhere: the whole share gathered first (one exchange), else each box
        // read from the file as its round comes.
        const bool from_memory = comm.max(retained.tiles ? 1.0 : 0.0) > 0;
        if (from_memory && !retained.tiling) throw std::logic_error("write_result: tiles kept without their tiling");
        std::vector<BoxData> gathered;
        if (from_memory) gathered = gather_share(comm, retained, chunks, share, count_bytes, read);
        const h5::Id collective = h5::plist_id(H5Pcreate(H5P_DATASET_XFER), "H5Pcreate");
        h5::check(H5Pset_dxpl_mpio(collective, H5FD_MPIO_COLLECTIVE), "H5Pset_dxpl_mpio");
        BoxData buffer;
        for (std::size_t round = 0; round < rounds; ++round) {
            const h5::Id file_space = h5::space_id(H5Dget_space(counts), "H5Dget_space");
            h5::Id memory;
            const BoxData* d = &buffer;
            if (round < mine.size()) {
                const Box& b = mine[round].box;
                h5::select_box(file_space, to_hsize(b.start), to_hsize(b.count));
                memory = h5::simple_space(to_hsize(b.count));
                if (from_memory) {
                    d = &gathered[round];
                } else {
                    buffer.counts.resize(b.points() * count_bytes);
                    buffer.outcomes.resize(b.points());
                    read(b, buffer);
                }
            } else {
                h5::check(H5Sselect_none(file_space), "H5Sselect_none");
                memory = h5::simple_space({1});
                h5::check(H5Sselect_none(memory), "H5Sselect_none");
                buffer.counts.resize(count_bytes);
                buffer.outcomes.resize(1);
            }
            h5::check(H5Dwrite(counts, counts_memory, memory, file_space, collective, d->counts.data()),
                      "write /wall_bounces of " + tmp.string());
            h5::check(H5Dwrite(outcomes, H5T_NATIVE_UINT8, memory, file_space, collective, d->outcomes.data()),
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
