// The partial file of a run in progress (io/layout.hpp), which becomes the result when
// the run completes. Created by rank 0 with serial HDF5: every object of the result
// (coordinates, attributes, /wall_bounces and /outcome chunked one chunk per tile) and
// the resume journal (/progress). During the run the HDF5 metadata never change, so the
// file is consistent at every moment; tiles reach it in one of two ways:
//
//  - compressed (the default): each rank compresses a tile when it has counted it
//    (io/chunk_codec.hpp) and sends the bytes to rank 0, whose ChunkAppender writes them
//    one after the other past the end of the HDF5 objects; the journal records where. At
//    the end rank 0 indexes them where they lie (io/placed_chunks.hpp, final_result.hpp):
//    nothing is read back or written twice. Compressed tiles are 0.2-30 % of the raw
//    data, so one writer carries many ranks;
//  - uncompressed (`[run] compression = 0`): every chunk is allocated at creation,
//    contiguous and aligned (HDF5's implicit chunk index), and each rank writes its tiles
//    straight to their offsets (TileWriter).
//
// Crash safety: a tile is recorded done in the journal (written by rank 0 only) after its
// bytes and checksum are written, so a process killed at any moment leaves a file in which
// every tile marked done holds its data. A resume checks the done tiles against their
// checksums (PartialFile::damaged) and refuses a damaged file.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <future>
#include <optional>
#include <span>
#include <vector>

#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "job/tiles.hpp"
#include "page_buffer.hpp"
#include "posix_file.hpp"
#include "stored_tiles.hpp"

namespace superball {

// Where the data and the journal of a partial file lie: byte offsets and sizes, the same
// on every rank.
struct PartialLayout {
    bool compressed = false;         // tiles appended compressed, else at fixed offsets
    std::uint64_t level = 0;         // the deflate level of a compressed file
    std::uint64_t counts_at = 0;     // uncompressed: chunk 0 of /wall_bounces (chunk t at t * counts_chunk)
    std::uint64_t outcomes_at = 0;   // uncompressed: chunk 0 of /outcome
    std::uint64_t done_at = 0;       // /progress/tile_done[0] (one byte per tile)
    std::uint64_t checksums_at = 0;  // /progress/tile_checksum[0] (8 bytes per tile, little-endian)
    std::uint64_t stored_at = 0;     // compressed: /progress/tile_stored[0] (3 x 8 bytes per tile)
    std::uint64_t count_bytes = 2;   // bytes of one count: 2 (uint16) or 4 (uint32)
    std::uint64_t chunk_points = 0;  // points of a chunk (a full tile)
    std::uint64_t tiles = 0;

    std::uint64_t counts_chunk() const { return chunk_points * count_bytes; }
    std::uint64_t outcomes_chunk() const { return chunk_points; }
};

// Rank 0 only: creates the partial file of `job` at `path` (replacing any file there) for
// the run `run` (its ranks, its provenance), compressed at the job's level unless it is 0,
// and returns its layout. The coordinate variables and attributes are those of a result;
// wall_seconds starts at zero.
PartialLayout create_partial(const std::filesystem::path& path, const Job& job, const Grid& grid, const Tiling& tiling,
                             const Provenance& run);
// Rank 0 only: the layout of an existing partial file (validated by ResultReader before):
// compressed or not as it was created, whatever the job says now.
PartialLayout partial_layout(const std::filesystem::path& path, const Tiling& tiling);
// Rank 0 only, with no rank holding the file open: adds a run's seconds to wall_seconds and
// records the run (its ranks, its line of history); returns the new wall_seconds. Keeps
// every byte of the file (chunks appended past HDF5's own end included).
double record_partial_run(const std::filesystem::path& path, double seconds, const Provenance& run);

// The partial file of a run, opened by each process that uses it on a descriptor of its own.
class PartialFile {
public:
    // Opened at once: the threads of a run in one process share the descriptor (positioned
    // reads and writes).
    PartialFile(const std::filesystem::path& path, Tiling tiling, const PartialLayout& layout);
    // Opened when first used, by a rank of a run over MPI: of a compressed run only the
    // writers and a resume's checks do, so thousands of ranks do not queue at the file
    // system's metadata server to open a file they never touch.
    struct OnFirstUse {};
    PartialFile(const std::filesystem::path& path, Tiling tiling, const PartialLayout& layout, OnFirstUse);

    const Tiling& tiling() const { return tiling_; }
    const PartialLayout& layout() const { return layout_; }
    const std::filesystem::path& path() const { return path_; }
    // Opens the file on first use (std::system_error naming it if it cannot).
    const PosixFile& file() const;

    // Of the tiles `done` (ascending) with the checksums recorded for them (and, compressed,
    // where they lie), those whose data no longer match. A run over several processes gives
    // each a share and gathers what they found (run/lifecycle.cpp).
    std::vector<std::uint64_t> damaged(std::span<const std::uint64_t> done, std::span<const std::uint64_t> checksums,
                                       std::span<const StoredChunk> stored);

    // Closes this rank's descriptor, if open (after every write of the rank's writers).
    void close()
    {
        if (file_) file_->close();
    }

private:
    std::filesystem::path path_;
    Tiling tiling_;
    PartialLayout layout_;
    mutable std::optional<PosixFile> file_;  // opened by file() (OnFirstUse), else at once
};

// Places a tile's values, row-major over its box, in the layout of its chunk: row-major
// over the tile shape, the points of an edge tile's chunk beyond the grid zero. `chunk`
// holds tiling.tile_points() values; returns it, or `values` itself when the tile is full.
template <class T>
std::span<const T> in_chunk_layout(const Tiling& tiling, std::uint64_t tile, std::span<const T> values, std::vector<T>& chunk)
{
    const Box box = tiling.box(tile);
    if (box.count == tiling.tile_shape()) return values;
    chunk.assign(tiling.tile_points(), T{0});
    copy_box(box, std::as_bytes(values).data(), box.start, box.count, reinterpret_cast<std::byte*>(chunk.data()), box.start,
             tiling.tile_shape(), sizeof(T));
    return chunk;
}

// Compressed tiles on their way to rank 0's ChunkAppender: those a rank counted since it
// last flushed, their stored chunks one after the other.
struct TileBatch {
    // Per tile: tile, checksum, bytes of its stored counts, bytes of its stored outcomes.
    std::vector<std::uint64_t> entries;
    std::vector<std::byte> data;  // each tile's counts then outcomes, in entry order

    static constexpr std::size_t words = 4;
    std::size_t tiles() const { return entries.size() / words; }
    bool empty() const { return entries.empty(); }
    void clear()
    {
        entries.clear();
        data.clear();
    }
    // The tiles' reports, in order.
    std::vector<TileReport> reports() const;
    // One buffer holding the batch, for a message: [tiles][entries][data].
    std::vector<std::byte> pack() const;
    // The batch a message holds; std::runtime_error if it is not one.
    static TileBatch unpack(std::span<const std::byte> message);
};

// A writer of compressed tiles (rank 0's, and with several writers each node leader's that
// writes, run/work_pool.hpp): batches are placed in the file space the writer holds, copied
// into a buffer and written (by a thread of its own, so the copy into the file system
// overlaps with counting and serving; at once when no write is in progress, else gathered
// with the next batches), then reported written with their addresses. The only writer holds
// the file from its end on; one of several holds the space rank 0 granted it (whole stripes,
// so that no two writers share one), asks for more ahead of need, and places a tile where
// it fits whole (a range's end too short for the next tile stays unused).
class ChunkAppender {
public:
    // File space granted by rank 0 to one of several writers: ask for this many bytes more
    // than the tiles waiting need (a stripe), so that a write rarely waits for a round trip.
    struct Granted {
        std::uint64_t ahead = 0;
    };

    // The only writer: appends from byte `start` on (the file's end: nothing there is
    // overwritten).
    ChunkAppender(PartialFile& file, std::uint64_t start, std::uint64_t buffer_bytes);
    // One of several: places tiles only in the space given by grant().
    ChunkAppender(PartialFile& file, Granted space, std::uint64_t buffer_bytes);

    void add(const TileBatch& batch);
    // Bytes of file space it needs beyond what it holds to place what waits and `more`
    // bytes (0: none; always 0 alone).
    std::uint64_t wanted(std::uint64_t more = 0) const;
    // [address, address + bytes) is this writer's (rank 0 granted it).
    void grant(std::uint64_t address, std::uint64_t bytes);
    // The tiles written since the last call (without waiting for writes in progress); starts
    // writing what waits when no write is in progress.
    std::vector<AppendedTile> written();
    // Writes what is buffered and waits for every write; the tiles written since the
    // last call. std::logic_error if a tile still waits for file space.
    std::vector<AppendedTile> flush();
    // Some tile added has not been returned written yet.
    bool holding() const;
    // More bytes wait for file space than one buffer holds.
    bool full() const { return waiting_bytes_ > capacity_; }

private:
    struct Buffer {
        std::vector<std::byte> bytes;
        std::uint64_t at = 0;  // the address of bytes[0]
        std::vector<AppendedTile> tiles;
        std::future<void> write;  // valid while being written
    };
    struct Range {
        std::uint64_t at = 0, end = 0;  // unused space [at, end)
    };
    // Places `batch`'s tiles from `next` on (their data from `data_at`) in the space held, in
    // runs that each go to one buffer; returns the first tile that found no space.
    std::size_t place(const TileBatch& batch, std::size_t next, std::size_t& data_at);
    // Places what waits for space, then `batch` (or keeps it waiting), and writes as add() says.
    void place_all(const TileBatch* batch);
    void issue();
    void complete(Buffer& b);
    bool in_flight(const Buffer& b) const;

    PartialFile& file_;
    std::uint64_t capacity_;
    bool alone_;
    std::uint64_t ahead_ = 0;
    std::deque<Range> space_;
    TileBatch waiting_;  // tiles with no space yet, from waiting_next_ (data from waiting_at_)
    std::size_t waiting_next_ = 0, waiting_at_ = 0;
    std::uint64_t waiting_bytes_ = 0;
    Buffer buffers_[2];
    int current_ = 0;
    std::vector<AppendedTile> written_;
};

// One rank's writer of uncompressed tiles: tiles computed one after the other are placed in
// their chunk layout in a buffer, and each run of consecutive tiles leaves as one write
// per dataset when the buffer is full, when a tile does not follow the last, or on
// flush(). Two buffers: one is written (by a thread of its own, posix_file.hpp) while the
// next fills, so the copy into the file system overlaps with counting.
class TileWriter {
public:
    // buffer_bytes: of counts per buffer, at least one chunk (outcomes take half or a
    // quarter of it).
    TileWriter(PartialFile& file, std::uint64_t buffer_bytes);

    // The tile's values, row-major over its box (counts never above 2^16 - 1 in a 16-bit
    // file: the job's max_bounces says so).
    void add(std::uint64_t tile, std::span<const std::uint32_t> counts, std::span<const std::uint8_t> outcomes);
    // Writes what is buffered and waits for every write; returns the tiles written since
    // the last call, with their checksums, in the order they were added.
    std::vector<TileReport> flush();

private:
    struct Buffer {
        PageArray<std::uint16_t> counts16;  // 16-bit files
        PageArray<std::uint32_t> counts32;  // 32-bit files
        PageArray<std::uint8_t> outcomes;
        std::uint64_t first = 0, count = 0;   // tiles [first, first + count)
        std::vector<TileReport> reports;
        std::future<void> written;  // valid while the buffer is being written
    };
    // Starts writing the current buffer and moves on to the other one.
    void issue();
    // Waits for buffer b's writes; its tiles join written_.
    void complete(Buffer& b);

    PartialFile& file_;
    std::uint64_t capacity_tiles_;
    Buffer buffers_[2];
    int current_ = 0;
    std::vector<TileReport> written_;
};

// Rank 0's record of finished tiles in the partial file's /progress datasets: where each
// tile lies and its checksum written as the tile is recorded (one write per run of
// consecutive tiles), the done flags that vouch for them kept in memory (a byte a tile: the
// rest of the record is the file's, so that rank 0's memory does not grow by 33 bytes a
// tile) and written at most every `interval` seconds and when asked.
class Journal {
public:
    // `done`: the done flags so far (a resume), one per tile.
    Journal(PartialFile& file, std::vector<std::uint8_t> done, std::chrono::duration<double> interval);

    void record(std::span<const TileReport> tiles);    // uncompressed files
    void record(std::span<const AppendedTile> tiles);  // compressed files
    // Writes the done flags changed since the last write, if `interval` has passed or `now`
    // is true; true if it wrote.
    bool checkpoint(bool now);
    // `interval` has passed since the last write.
    bool due() const;
    std::uint64_t tiles_done() const { return tiles_done_; }
    std::span<const std::uint8_t> done() const { return done_; }

private:
    void mark(std::uint64_t tile);
    // Writes `bytes` at `offset` of the file, for tiles `first` to `last`; h5::Error naming
    // them (and the file system's free space) if it cannot.
    void write(std::uint64_t offset, const void* data, std::size_t bytes, std::uint64_t first, std::uint64_t last) const;

    PartialFile& file_;
    std::vector<std::uint8_t> done_;
    std::chrono::duration<double> interval_;
    std::chrono::steady_clock::time_point last_;
    std::uint64_t dirty_begin_, dirty_end_ = 0;  // tiles whose flag changed since the last write
    std::uint64_t tiles_done_ = 0;
    // A run of consecutive tiles' checksums and places, as they are written.
    std::vector<std::uint64_t> run_checksums_;
    std::vector<StoredChunk> run_stored_;
};

// Where the compressed tiles [first, first + count) lie, as the partial file's journal
// records them (io/layout.hpp: /progress/tile_stored; read from its place in the file).
std::vector<StoredChunk> read_stored(const PosixFile& file, const PartialLayout& layout, std::uint64_t first,
                                     std::uint64_t count);

// What the journal records of some tiles: their checksums and, compressed, where they lie.
struct JournalRecord {
    std::vector<std::uint64_t> checksums;
    std::vector<StoredChunk> stored;  // compressed files only (else empty)
};
// The record of `tiles` (ascending), read from the partial file a window of tiles at a time,
// so that reading the record of a few tiles spread over the grid holds little more than
// theirs.
JournalRecord read_journal(const PartialFile& file, std::span<const std::uint64_t> tiles);

}  // namespace superball
