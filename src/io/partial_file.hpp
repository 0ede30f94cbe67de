// The partial file of a run in progress (io/layout.hpp): created by rank 0 with serial
// HDF5, every chunk (one per tile) allocated contiguously and aligned, nothing filled;
// during the run every rank writes its tiles through MPI-IO straight to their offsets, so
// the HDF5 metadata never change and the file is consistent at every moment.
//
// Crash safety: a tile is recorded done in the journal (/progress/tile_done, written by
// rank 0 only) after its data and checksum are written, so a process killed at any
// moment leaves a file in which every tile marked done holds its data. A resume checks the
// done tiles against their checksums (PartialFile::damaged) and refuses a damaged file.
#pragma once

#include <chrono>
#include <future>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/tiles.hpp"
#include "mpi/mpi.hpp"
#include "page_buffer.hpp"
#include "posix_file.hpp"
#include "retained_tiles.hpp"

namespace superball {

// Where the data of a partial file lie: byte offsets and sizes, the same on every rank.
struct PartialLayout {
    std::uint64_t counts_at = 0;     // chunk 0 of /wall_bounces (chunk t follows at t * counts_chunk)
    std::uint64_t outcomes_at = 0;   // chunk 0 of /outcome
    std::uint64_t done_at = 0;       // /progress/tile_done[0] (one byte per tile)
    std::uint64_t checksums_at = 0;  // /progress/tile_checksum[0] (8 bytes per tile, little-endian)
    std::uint64_t count_bytes = 2;   // bytes of one count: 2 (uint16) or 4 (uint32)
    std::uint64_t chunk_points = 0;  // points of a chunk (a full tile)
    std::uint64_t tiles = 0;

    std::uint64_t counts_chunk() const { return chunk_points * count_bytes; }
    std::uint64_t outcomes_chunk() const { return chunk_points; }
};

// The checksum of a tile as the partial file stores it: XXH3-64 (xxHash, a stable format)
// of the tile's chunk of /wall_bounces then its chunk of /outcome, as stored (little-endian,
// a chunk's points beyond the grid's edge zero), seeded with the tile's number.
std::uint64_t tile_checksum(std::uint64_t tile, std::span<const std::byte> counts_chunk,
                            std::span<const std::byte> outcomes_chunk);

// Rank 0 only: creates the partial file of `job` at `path` (replacing any file there) for
// `ranks` ranks, and returns its layout. The coordinate variables and attributes are those
// of a result; the run's figures (wall_seconds, mpi_ranks) start at zero.
PartialLayout create_partial(const std::filesystem::path& path, const Job& job, const Grid& grid, const Tiling& tiling,
                             int ranks);
// Rank 0 only: the layout of an existing partial file (validated by ResultReader before).
PartialLayout partial_layout(const std::filesystem::path& path, const Tiling& tiling);
// Rank 0 only, with no rank holding the file open: adds a run's seconds to wall_seconds and
// records its rank count; returns the new wall_seconds.
double record_partial_run(const std::filesystem::path& path, double seconds, int ranks);

// The partial file opened by every rank of a run, each on its own descriptor.
class PartialFile {
public:
    PartialFile(const std::filesystem::path& path, const mpi::Comm& comm, Tiling tiling, const PartialLayout& layout);

    const Tiling& tiling() const { return tiling_; }
    const PartialLayout& layout() const { return layout_; }
    const std::filesystem::path& path() const { return path_; }
    const PosixFile& file() const { return file_; }

    // Collective: of the tiles `done` (identical on every rank, ascending) with the
    // checksums recorded for them, those whose data no longer match, on every rank. Each
    // rank reads its share.
    std::vector<std::uint64_t> damaged(std::span<const std::uint64_t> done, std::span<const std::uint64_t> checksums);

    // Closes this rank's descriptor (after every write of the rank's TileWriter).
    void close() { file_.close(); }

private:
    std::filesystem::path path_;
    const mpi::Comm& comm_;
    Tiling tiling_;
    PartialLayout layout_;
    PosixFile file_;
};

// One rank's writer: tiles computed one after the other are placed in their chunk layout in
// a buffer, and each run of consecutive tiles leaves as one write per dataset when the
// buffer is full, when a tile does not follow the last, or on flush(). Two buffers: one
// is written (by a thread of its own, posix_file.hpp) while the next fills, so the copy
// into the file system overlaps with counting.
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
    // From now on, every tile added is also kept in `store` while its budget lasts (for the
    // closing pass, final_result.hpp). The store outlives the writer.
    void retain(RetainedTiles& store) { retained_ = &store; }

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
    RetainedTiles* retained_ = nullptr;
};

// Rank 0's record of finished tiles: kept in memory, written to the partial file's
// /progress datasets (checksums first, then done flags) at most every `interval` seconds
// and when asked.
class Journal {
public:
    // `done`, `checksums`: the record so far (a resume), one entry per tile.
    Journal(PartialFile& file, std::vector<std::uint8_t> done, std::vector<std::uint64_t> checksums,
            std::chrono::duration<double> interval);

    void record(std::span<const TileReport> tiles);
    // Writes what changed since the last write, if `interval` has passed or `now` is true.
    void checkpoint(bool now);
    std::uint64_t tiles_done() const { return tiles_done_; }

private:
    PartialFile& file_;
    std::vector<std::uint8_t> done_;
    std::vector<std::uint64_t> checksums_;
    std::chrono::duration<double> interval_;
    std::chrono::steady_clock::time_point last_;
    std::uint64_t dirty_begin_, dirty_end_ = 0;  // tiles changed since the last write
    std::uint64_t tiles_done_ = 0;
};

}  // namespace superball
