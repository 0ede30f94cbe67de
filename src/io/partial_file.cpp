#include "partial_file.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "hdf5.hpp"
#include "layout.hpp"
#include "placed_chunks.hpp"
#include "result_metadata.hpp"

namespace superball {

static_assert(std::endian::native == std::endian::little,
              "the partial file's journal and uncompressed chunks are written as bytes in memory order: little-endian hosts "
              "only");

namespace {

// The data of a dataset, one chunk per tile. Uncompressed: every chunk allocated at
// creation and never filled; with the HDF5 1.10 format, no filter and early allocation,
// HDF5 indexes the chunks implicitly (chunk t lies at the dataset's first chunk plus t
// chunks: layout_of checks it), with no index to update, so ranks write chunks straight to
// their offsets. Compressed: the result's filter pipeline (shuffle, then deflate at
// `level`: every HDF5 reads it without plugins), no chunk allocated; the chunks are
// indexed where rank 0 appended them when the run completes.
void create_tiled(hid_t file, const char* name, hid_t type, const Tiling& tiling, int level)
{
    h5::create_dataset(file, name, type, h5::to_hsize(tiling.shape()),
                       {h5::to_hsize(tiling.tile_shape()), level, level > 0 ? H5D_ALLOC_TIME_INCR : H5D_ALLOC_TIME_EARLY,
                        H5D_FILL_TIME_NEVER});
}

// A contiguous dataset of one row per tile, zeros (no tile done yet).
void create_journal(hid_t loc, const char* name, hid_t type, hsize_t n, hsize_t per_tile = 1)
{
    h5::create_dataset(loc, name, type, per_tile == 1 ? std::vector<hsize_t>{n} : std::vector<hsize_t>{n, per_tile},
                       {{}, 0, H5D_ALLOC_TIME_EARLY, H5D_FILL_TIME_ALLOC});
}

// Chunk `t`'s first element, as dataset coordinates.
std::vector<hsize_t> chunk_origin(const Tiling& tiling, std::uint64_t t) { return h5::to_hsize(tiling.box(t).start); }

PartialLayout layout_of(hid_t file, const Tiling& tiling)
{
    PartialLayout l;
    l.tiles = tiling.tiles();
    l.chunk_points = tiling.tile_points();
    const h5::Id counts = h5::open_dataset(file, layout::wall_bounces);
    const h5::Id outcomes = h5::open_dataset(file, layout::outcome);
    l.count_bytes = h5::dataset_shape_of(counts).bytes;
    const h5::Storage st = h5::dataset_storage(counts);
    l.compressed = st.filters > 0;
    l.done_at = h5::contiguous_offset(h5::open_dataset(file, layout::tile_done));
    l.checksums_at = h5::contiguous_offset(h5::open_dataset(file, layout::tile_checksum));
    if (l.compressed) {
        if (st.deflate_level < 1 || st.deflate_level > 9 || !st.shuffle) {
            throw h5::Error("the partial file's /wall_bounces is compressed otherwise than with shuffle and deflate 1-9");
        }
        l.level = static_cast<std::uint64_t>(st.deflate_level);
        l.stored_at = h5::contiguous_offset(h5::open_dataset(file, layout::tile_stored));
        return l;
    }
    const auto contiguous_chunks = [&](hid_t d, std::uint64_t chunk_bytes) {
        const std::uint64_t first = h5::chunk_offset(d, chunk_origin(tiling, 0));
        const std::uint64_t last = h5::chunk_offset(d, chunk_origin(tiling, l.tiles - 1));
        // The implicit chunk index allocates every chunk in one piece, in order. A file laid
        // out otherwise (another writer, a future HDF5) is refused rather than scribbled on.
        if (last != first + (l.tiles - 1) * chunk_bytes) {
            throw h5::Error("the chunks of the partial file are not laid out one after the other");
        }
        return first;
    };
    l.counts_at = contiguous_chunks(counts, l.counts_chunk());
    l.outcomes_at = contiguous_chunks(outcomes, l.outcomes_chunk());
    return l;
}

// Places a tile's values, row-major over its box, into its chunk (row-major over the tile
// shape; an edge tile's box is smaller and the rest of the chunk stays as it is),
// converting each value with `put` (a narrowing copy, fused with the placement).
template <class Put>
void place(const Extent& box_count, const Extent& tile_shape, std::size_t n, Put&& put)
{
    const std::size_t d = tile_shape.size();
    const std::size_t row = box_count[d - 1];
    if (box_count == tile_shape) {
        for (std::size_t i = 0; i < n; ++i) put(i, i);
        return;
    }
    // Strides of the chunk.
    Extent stride(d, 1);
    for (std::size_t k = d - 1; k-- > 0;) stride[k] = stride[k + 1] * tile_shape[k + 1];
    Extent index(d, 0);
    for (std::size_t src = 0; src < n; src += row) {
        std::size_t dst = 0;
        for (std::size_t k = 0; k < d; ++k) dst += index[k] * stride[k];
        for (std::size_t j = 0; j < row; ++j) put(dst + j, src + j);
        for (std::size_t k = d - 1; k-- > 0;) {
            if (++index[k] < box_count[k]) break;
            index[k] = 0;
        }
    }
}

}  // namespace

PartialLayout create_partial(const std::filesystem::path& path, const Job& job, const Grid& grid, const Tiling& tiling,
                             const Provenance& run)
{
    const h5::Id fapl = h5::file_access(job.alignment);
    const h5::Id file = h5::create_file(path, fapl);
    {
        // The journal first: small, next to the metadata, away from the stripes of the data.
        const h5::Id progress = h5::create_group(file, "/progress");
        create_journal(file, layout::tile_done, H5T_STD_U8LE, tiling.tiles());
        create_journal(file, layout::tile_checksum, H5T_STD_U64LE, tiling.tiles());
        if (job.compression > 0) create_journal(file, layout::tile_stored, H5T_STD_U64LE, tiling.tiles(), 3);
    }
    create_tiled(file, layout::wall_bounces, count_type(job), tiling, job.compression);
    create_tiled(file, layout::outcome, H5T_STD_U8LE, tiling, job.compression);
    const std::vector<h5::Id> axes = write_metadata(file, job, grid, layout::kind_partial, {run, 0.0, false}, true);
    {
        const h5::Id counts = h5::open_dataset(file, layout::wall_bounces);
        const h5::Id outcomes = h5::open_dataset(file, layout::outcome);
        describe_data(counts, outcomes, job, axes);
    }
    h5::write_attribute(file, layout::attr::tile_shape, tiling.tile_shape());
    PartialLayout l = layout_of(file, tiling);
    h5::flush(file);
    return l;
}

PartialLayout partial_layout(const std::filesystem::path& path, const Tiling& tiling)
{
    return layout_of(h5::open_file(path, false), tiling);
}

double record_partial_run(const std::filesystem::path& path, double seconds, const Provenance& run)
{
    PlacedChunks file(path);
    const double total = h5::read_double_attribute(file.file(), layout::attr::wall_seconds) + seconds;
    write_run_figures(file.file(), {run, total, false});
    file.close();
    PlacedChunks::discard_undo(path);
    return total;
}

// ------------------------------------------------------------------------- PartialFile

PartialFile::PartialFile(const std::filesystem::path& path, Tiling tiling, const PartialLayout& layout)
    : path_(path), tiling_(std::move(tiling)), layout_(layout), file_(std::in_place, path)
{
}

PartialFile::PartialFile(const std::filesystem::path& path, Tiling tiling, const PartialLayout& layout, OnFirstUse)
    : path_(path), tiling_(std::move(tiling)), layout_(layout)
{
}

const PosixFile& PartialFile::file() const
{
    if (!file_) file_.emplace(path_);
    return *file_;
}

std::vector<std::uint64_t> PartialFile::damaged(std::span<const std::uint64_t> done, std::span<const std::uint64_t> checksums,
                                                std::span<const StoredChunk> stored)
{
    std::vector<std::uint64_t> bad;
    std::vector<std::byte> counts, outcomes;
    if (layout_.compressed) {
        const std::uint64_t size = file().size();
        for (std::uint64_t i = 0; i < done.size(); ++i) {
            const StoredChunk& s = stored[i];
            if (s.end() > size || s.end() < s.address) {
                bad.push_back(done[i]);
                continue;
            }
            counts.resize(s.counts_bytes + s.outcomes_bytes);
            file().read_at(s.address, counts.data(), counts.size());
            const std::span<const std::byte> all(counts);
            if (tile_checksum(done[i], all.first(s.counts_bytes), all.subspan(s.counts_bytes)) != checksums[i]) {
                bad.push_back(done[i]);
            }
        }
    } else {
        // Runs of consecutive tiles are read in one piece.
        const std::uint64_t cb = layout_.counts_chunk(), ob = layout_.outcomes_chunk();
        constexpr std::uint64_t max_run = std::uint64_t{8} << 20;
        const std::uint64_t run_tiles = std::max<std::uint64_t>(1, max_run / cb);
        const std::uint64_t end = done.size();
        for (std::uint64_t i = 0; i < end;) {
            std::uint64_t n = 1;
            while (i + n < end && n < run_tiles && done[i + n] == done[i] + n) ++n;
            counts.resize(n * cb);
            outcomes.resize(n * ob);
            file().read_at(layout_.counts_at + done[i] * cb, counts.data(), counts.size());
            file().read_at(layout_.outcomes_at + done[i] * ob, outcomes.data(), outcomes.size());
            for (std::uint64_t j = 0; j < n; ++j) {
                const std::span<const std::byte> c(counts.data() + j * cb, cb), o(outcomes.data() + j * ob, ob);
                if (tile_checksum(done[i + j], c, o) != checksums[i + j]) bad.push_back(done[i + j]);
            }
            i += n;
        }
    }
    return bad;
}

// ---------------------------------------------------------------------------- TileBatch

std::vector<TileReport> TileBatch::reports() const
{
    std::vector<TileReport> r(tiles());
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = {entries[words * i], entries[words * i + 1]};
    return r;
}

std::vector<std::byte> TileBatch::pack() const
{
    const std::uint64_t n = tiles();
    std::vector<std::byte> out(8 * (1 + entries.size()) + data.size());
    std::memcpy(out.data(), &n, 8);
    // An empty batch (a worker handing over before it has a tile) has no buffers at all, and
    // memcpy from a null pointer is undefined even for 0 bytes (UBSan stops on it).
    if (!entries.empty()) std::memcpy(out.data() + 8, entries.data(), 8 * entries.size());
    if (!data.empty()) std::memcpy(out.data() + 8 * (1 + entries.size()), data.data(), data.size());
    return out;
}

TileBatch TileBatch::unpack(std::span<const std::byte> message)
{
    TileBatch b;
    std::uint64_t n = 0;
    if (message.size() < 8) throw std::runtime_error("a batch of tiles shorter than its header");
    std::memcpy(&n, message.data(), 8);
    if (n > (message.size() - 8) / (8 * words)) throw std::runtime_error("a batch of tiles shorter than its entries");
    b.entries.resize(n * words);
    if (n > 0) std::memcpy(b.entries.data(), message.data() + 8, 8 * b.entries.size());
    std::uint64_t bytes = 0;
    for (std::uint64_t i = 0; i < n; ++i) bytes += b.entries[words * i + 2] + b.entries[words * i + 3];
    const std::size_t at = 8 * (1 + b.entries.size());
    if (message.size() - at != bytes) throw std::runtime_error("a batch of tiles whose data do not match its entries");
    b.data.assign(message.begin() + static_cast<std::ptrdiff_t>(at), message.end());
    return b;
}

// ------------------------------------------------------------------------ ChunkAppender

ChunkAppender::ChunkAppender(PartialFile& file, std::uint64_t start, std::uint64_t buffer_bytes)
    : file_(file), capacity_(buffer_bytes), alone_(true)
{
    space_.push_back({start, std::numeric_limits<std::uint64_t>::max()});
}

ChunkAppender::ChunkAppender(PartialFile& file, Granted space, std::uint64_t buffer_bytes)
    : file_(file), capacity_(buffer_bytes), alone_(false), ahead_(space.ahead)
{
}

void ChunkAppender::add(const TileBatch& batch)
{
    // A batch that would take the buffer past its size first sends the buffer off (a single
    // batch larger than that is written whole).
    const Buffer& b = buffers_[current_];
    if (!b.bytes.empty() && b.bytes.size() + batch.data.size() > capacity_) issue();
    place_all(&batch);
}

void ChunkAppender::grant(std::uint64_t address, std::uint64_t bytes)
{
    if (alone_) throw std::logic_error("ChunkAppender: file space granted to the only writer");
    if (!space_.empty() && space_.back().end == address) {
        space_.back().end += bytes;  // the next stripes: one range, nothing skipped between
    } else {
        space_.push_back({address, address + bytes});
    }
    place_all(nullptr);
}

std::size_t ChunkAppender::place(const TileBatch& batch, std::size_t next, std::size_t& data_at)
{
    const auto size = [&](std::size_t i) { return batch.entries[TileBatch::words * i + 2] + batch.entries[TileBatch::words * i + 3]; };
    while (next < batch.tiles()) {
        // A range's end too short for the next tile stays unused (a hole in the file).
        while (!space_.empty() && space_.front().end - space_.front().at < size(next)) space_.pop_front();
        if (space_.empty()) break;
        Range& r = space_.front();
        // One write is one run of the file: a range apart from the buffer's starts another.
        if (const Buffer& b = buffers_[current_]; !b.bytes.empty() && b.at + b.bytes.size() != r.at) issue();
        Buffer& b = buffers_[current_];
        if (b.bytes.empty()) b.at = r.at;
        std::uint64_t bytes = 0;
        for (; next < batch.tiles() && bytes + size(next) <= r.end - r.at; ++next) {
            const std::uint64_t* e = batch.entries.data() + TileBatch::words * next;
            b.tiles.push_back({e[0], e[1], {r.at + bytes, e[2], e[3]}});
            bytes += size(next);
        }
        const auto from = batch.data.begin() + static_cast<std::ptrdiff_t>(data_at);
        b.bytes.insert(b.bytes.end(), from, from + static_cast<std::ptrdiff_t>(bytes));
        r.at += bytes;
        data_at += bytes;
    }
    return next;
}

void ChunkAppender::place_all(const TileBatch* batch)
{
    if (waiting_next_ < waiting_.tiles()) {
        const std::size_t at = waiting_at_;
        waiting_next_ = place(waiting_, waiting_next_, waiting_at_);
        waiting_bytes_ -= waiting_at_ - at;
        if (waiting_next_ == waiting_.tiles()) {
            waiting_.clear();
            waiting_next_ = waiting_at_ = 0;
        }
    }
    if (batch) {
        // Straight from the batch while nothing waits before it (no copy); what finds no
        // space waits, in order.
        std::size_t next = 0, at = 0;
        if (waiting_.empty()) next = place(*batch, 0, at);
        for (std::size_t i = next; i < batch->tiles(); ++i) {
            const auto* e = batch->entries.data() + TileBatch::words * i;
            waiting_.entries.insert(waiting_.entries.end(), e, e + TileBatch::words);
        }
        waiting_.data.insert(waiting_.data.end(), batch->data.begin() + static_cast<std::ptrdiff_t>(at), batch->data.end());
        waiting_bytes_ += batch->data.size() - at;
    }
    // Written at once when no write is in progress (the journal lags the counting by
    // little), else gathered until the write in progress is done or the buffer is full.
    if (buffers_[current_].bytes.size() >= capacity_ || !in_flight(buffers_[1 - current_])) issue();
}

std::uint64_t ChunkAppender::wanted(std::uint64_t more) const
{
    if (alone_) return 0;
    std::uint64_t held = 0;
    for (const Range& r : space_) held += r.end - r.at;
    const std::uint64_t need = waiting_bytes_ + more + ahead_;
    return need > held ? need - held : 0;
}

bool ChunkAppender::in_flight(const Buffer& b) const
{
    return b.write.valid() && b.write.wait_for(std::chrono::seconds(0)) != std::future_status::ready;
}

void ChunkAppender::issue()
{
    Buffer& b = buffers_[current_];
    if (b.bytes.empty()) return;
    const PosixFile& f = file_.file();
    // A thread per write (a few per second at most): the buffer stays untouched until waited for.
    // The bytes on stable storage before their tiles are reported written: a writer's node
    // that dies (its page cache with it) then cannot take back tiles rank 0 has recorded,
    // which would make the partial file damaged for the resume. Compressed writes are few:
    // no measurable cost here (docs/decisions.md).
    b.write = std::async(std::launch::async, [&f, &b] {
        f.write_at(b.at, b.bytes.data(), b.bytes.size());
        f.sync_data();
    });
    current_ = 1 - current_;
    complete(buffers_[current_]);
}

void ChunkAppender::complete(Buffer& b)
{
    if (!b.write.valid()) return;
    try {
        b.write.get();
    } catch (const std::exception& e) {
        throw h5::Error(fmt::format("writing {} compressed tiles at byte {} of {} failed ({}){}; {}", b.tiles.size(), b.at,
                                    file_.path().string(), e.what(), free_space_note(file_.path()), resume_after_failure));
    }
    written_.insert(written_.end(), b.tiles.begin(), b.tiles.end());
    b.tiles.clear();
    b.bytes.clear();
}

std::vector<AppendedTile> ChunkAppender::written()
{
    Buffer& other = buffers_[1 - current_];
    if (other.write.valid() && !in_flight(other)) complete(other);
    if (!other.write.valid()) issue();
    return std::exchange(written_, {});
}

std::vector<AppendedTile> ChunkAppender::flush()
{
    if (waiting_next_ < waiting_.tiles()) throw std::logic_error("ChunkAppender::flush: tiles still wait for file space");
    // At most one buffer is being written, the other one; issue() waits for it before the
    // current buffer's write is waited for, so tiles keep their order.
    issue();
    complete(buffers_[1 - current_]);
    return std::exchange(written_, {});
}

bool ChunkAppender::holding() const
{
    return waiting_next_ < waiting_.tiles() || !written_.empty() ||
           std::any_of(std::begin(buffers_), std::end(buffers_), [](const Buffer& b) { return !b.bytes.empty(); });
}

// --------------------------------------------------------------------------- TileWriter

TileWriter::TileWriter(PartialFile& file, std::uint64_t buffer_bytes)
    : file_(file), capacity_tiles_(std::max<std::uint64_t>(1, buffer_bytes / file.layout().counts_chunk()))
{
}

void TileWriter::add(std::uint64_t tile, std::span<const std::uint32_t> counts, std::span<const std::uint8_t> outcomes)
{
    Buffer* b = &buffers_[current_];
    if (b->count > 0 && (tile != b->first + b->count || b->count == capacity_tiles_)) {
        issue();
        b = &buffers_[current_];
    }
    if (b->count == 0) b->first = tile;
    const PartialLayout& l = file_.layout();
    const std::uint64_t n = l.chunk_points;
    const Box box = file_.tiling().box(tile);
    const Extent& shape = file_.tiling().tile_shape();
    const bool edge = box.points() != n;  // the chunk's points beyond the grid stay zero
    const auto fill = [&](auto& v) {
        // Allocated whole at the first tile and reused; a chunk is written whole below.
        auto* chunk = v.reserve(capacity_tiles_ * n) + b->count * n;
        using T = std::remove_reference_t<decltype(*chunk)>;
        if (edge) std::fill(chunk, chunk + n, T{0});
        return chunk;
    };
    std::uint8_t* const o = fill(b->outcomes);
    std::span<const std::byte> counts_bytes;
    if (l.count_bytes == 2) {
        std::uint16_t* const c = fill(b->counts16);
        place(box.count, shape, counts.size(), [&](std::size_t dst, std::size_t src) {
            c[dst] = static_cast<std::uint16_t>(counts[src]);
        });
        counts_bytes = std::as_bytes(std::span(c, n));
    } else {
        std::uint32_t* const c = fill(b->counts32);
        place(box.count, shape, counts.size(), [&](std::size_t dst, std::size_t src) { c[dst] = counts[src]; });
        counts_bytes = std::as_bytes(std::span(c, n));
    }
    place(box.count, shape, outcomes.size(), [&](std::size_t dst, std::size_t src) { o[dst] = outcomes[src]; });
    b->reports.push_back({tile, tile_checksum(tile, counts_bytes, std::as_bytes(std::span(o, n)))});
    ++b->count;
}

void TileWriter::issue()
{
    Buffer& b = buffers_[current_];
    if (b.count == 0) return;
    const PartialLayout& l = file_.layout();
    const PosixFile& f = file_.file();
    const void* counts = l.count_bytes == 2 ? static_cast<const void*>(b.counts16.data()) : b.counts32.data();
    const std::uint64_t counts_at = l.counts_at + b.first * l.counts_chunk(), counts_bytes = b.count * l.counts_chunk();
    const std::uint64_t outcomes_at = l.outcomes_at + b.first * l.outcomes_chunk(), outcomes_bytes = b.count * l.outcomes_chunk();
    const void* outcomes = b.outcomes.data();
    // A thread per write (a few per second at most): the buffer stays untouched until waited for.
    b.written = std::async(std::launch::async, [&f, counts, counts_at, counts_bytes, outcomes, outcomes_at, outcomes_bytes] {
        f.write_at(counts_at, counts, counts_bytes);
        f.write_at(outcomes_at, outcomes, outcomes_bytes);
    });
    // The other buffer fills next, once its own writes are done.
    current_ = 1 - current_;
    complete(buffers_[current_]);
}

void TileWriter::complete(Buffer& b)
{
    if (b.count == 0) return;
    try {
        b.written.get();
    } catch (const std::exception& e) {
        throw h5::Error(fmt::format("writing tiles {} to {} to {} failed ({}){}; {}", b.first, b.first + b.count - 1,
                                    file_.path().string(), e.what(), free_space_note(file_.path()), resume_after_failure));
    }
    written_.insert(written_.end(), b.reports.begin(), b.reports.end());
    b.reports.clear();
    b.count = 0;
}

std::vector<TileReport> TileWriter::flush()
{
    // At most one buffer is being written, the other one; issue() waits for it before the
    // current buffer's writes are waited for, so reports keep the order of the tiles.
    issue();
    complete(buffers_[1 - current_]);
    return std::exchange(written_, {});
}

// ------------------------------------------------------------------------------ Journal

Journal::Journal(PartialFile& file, std::vector<std::uint8_t> done, std::chrono::duration<double> interval)
    : file_(file),
      done_(std::move(done)),
      interval_(interval),
      last_(std::chrono::steady_clock::now()),
      dirty_begin_(done_.size())
{
    tiles_done_ = static_cast<std::uint64_t>(std::count(done_.begin(), done_.end(), std::uint8_t{1}));
}

void Journal::write(std::uint64_t offset, const void* data, std::size_t bytes, std::uint64_t first, std::uint64_t last) const
{
    try {
        file_.file().write_at(offset, data, bytes);
    } catch (const std::exception& e) {
        throw h5::Error(fmt::format("recording tiles {} to {} done in {} failed ({}){}", first, last, file_.path().string(),
                                    e.what(), free_space_note(file_.path())));
    }
}

void Journal::mark(std::uint64_t tile)
{
    if (done_[tile] == 0) ++tiles_done_;
    done_[tile] = 1;
    dirty_begin_ = std::min(dirty_begin_, tile);
    dirty_end_ = std::max(dirty_end_, tile + 1);
}

namespace {

// Calls write_run(begin, end) for each run [begin, end) of `tiles` whose tile numbers follow
// one another, of at most 8192 tiles (a run's entries are gathered for one write: 256 KiB).
template <class Tile, class WriteRun>
void for_each_run(std::span<const Tile> tiles, WriteRun write_run)
{
    constexpr std::size_t longest = 8192;
    for (std::size_t begin = 0, end = 0; begin < tiles.size(); begin = end) {
        for (end = begin + 1; end < tiles.size() && end - begin < longest && tiles[end].tile == tiles[end - 1].tile + 1;) ++end;
        write_run(begin, end);
    }
}

}  // namespace

void Journal::record(std::span<const TileReport> tiles)
{
    const PartialLayout& l = file_.layout();
    for_each_run(tiles, [&](std::size_t begin, std::size_t end) {
        run_checksums_.clear();
        for (std::size_t i = begin; i < end; ++i) run_checksums_.push_back(tiles[i].checksum);
        const std::uint64_t first = tiles[begin].tile, last = tiles[end - 1].tile;
        write(l.checksums_at + 8 * first, run_checksums_.data(), 8 * run_checksums_.size(), first, last);
    });
    for (const TileReport& r : tiles) mark(r.tile);
}

void Journal::record(std::span<const AppendedTile> tiles)
{
    static_assert(sizeof(StoredChunk) == 24 && std::is_standard_layout_v<StoredChunk>);
    const PartialLayout& l = file_.layout();
    // Where the tiles lie and their checksums, before the flags that vouch for them.
    for_each_run(tiles, [&](std::size_t begin, std::size_t end) {
        run_checksums_.clear();
        run_stored_.clear();
        for (std::size_t i = begin; i < end; ++i) {
            run_checksums_.push_back(tiles[i].checksum);
            run_stored_.push_back(tiles[i].stored);
        }
        const std::uint64_t first = tiles[begin].tile, last = tiles[end - 1].tile;
        write(l.stored_at + 24 * first, run_stored_.data(), 24 * run_stored_.size(), first, last);
        write(l.checksums_at + 8 * first, run_checksums_.data(), 8 * run_checksums_.size(), first, last);
    });
    for (const AppendedTile& a : tiles) mark(a.tile);
}

bool Journal::due() const { return std::chrono::steady_clock::now() - last_ >= interval_; }

bool Journal::checkpoint(bool now)
{
    const auto t = std::chrono::steady_clock::now();
    if (!now && t - last_ < interval_) return false;
    last_ = t;
    if (dirty_end_ <= dirty_begin_) return false;
    write(file_.layout().done_at + dirty_begin_, done_.data() + dirty_begin_, dirty_end_ - dirty_begin_, dirty_begin_,
          dirty_end_ - 1);
    dirty_begin_ = done_.size();
    dirty_end_ = 0;
    return true;
}

std::vector<StoredChunk> read_stored(const PosixFile& file, const PartialLayout& layout, std::uint64_t first,
                                     std::uint64_t count)
{
    std::vector<StoredChunk> stored(count);
    file.read_at(layout.stored_at + 24 * first, stored.data(), 24 * count);
    return stored;
}

JournalRecord read_journal(const PartialFile& file, std::span<const std::uint64_t> tiles)
{
    const PartialLayout& l = file.layout();
    JournalRecord r;
    r.checksums.reserve(tiles.size());
    if (l.compressed) r.stored.reserve(tiles.size());
    constexpr std::uint64_t window = 65536;  // tiles: 2 MiB of the record at most
    std::vector<std::uint64_t> sums;
    for (std::size_t begin = 0, end = 0; begin < tiles.size(); begin = end) {
        const std::uint64_t first = tiles[begin];
        for (end = begin + 1; end < tiles.size() && tiles[end] - first < window;) ++end;
        const std::uint64_t count = tiles[end - 1] - first + 1;
        sums.resize(count);
        file.file().read_at(l.checksums_at + 8 * first, sums.data(), 8 * count);
        const std::vector<StoredChunk> stored = l.compressed ? read_stored(file.file(), l, first, count) : std::vector<StoredChunk>{};
        for (std::size_t i = begin; i < end; ++i) {
            r.checksums.push_back(sums[tiles[i] - first]);
            if (l.compressed) r.stored.push_back(stored[tiles[i] - first]);
        }
    }
    return r;
}

}  // namespace superball
