// The counting side of an explore run, shared by run_explore (one per MPI rank) and
// run_explore_threads (one per thread): counts the tiles it is given and hands them on,
// compressed into a batch for the writer (TileWork::flush's payload), or to a TileWriter
// of its own (uncompressed files).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/kernels.hpp"
#include "io/final_result.hpp"
#include "io/partial_file.hpp"
#include "io/stored_tiles.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "run/explore.hpp"
#include "run/schedule.hpp"

namespace superball {

class ExploreWork : public TileWork {
public:
    // The points of this worker's tiles by outcome code (outcome_count entries), then the
    // points the kernel counted (fewer than the tiles' with refinement), then the points of
    // its tiles.
    virtual std::vector<std::uint64_t> tallies() const = 0;
};

// `writer`: where uncompressed tiles go (nullptr for a compressed file). Every argument must
// outlive the work.
std::unique_ptr<ExploreWork> make_explore_work(const Job& job, const Grid& grid, const Tiling& tiling,
                                               const PartialLayout& layout, TileWriter* writer, CountKernel kernel);

// The partial file as a run starts on it: made anew (`fresh`: the tiling `ranks` ranks
// choose) or read for a resume. Throws RunError naming the file (and its file system's free
// space, when short). Called by one process only: rank 0, or run_explore_threads.
struct StartedPartial {
    Extent tile_shape;
    PartialLayout layout;
    std::vector<std::uint8_t> done;  // the journal's done flags, a byte a tile
    double earlier_seconds = 0;      // of the runs before a resume
};
StartedPartial start_partial(const std::filesystem::path& partial, PlanMode mode, const Job& job, const Grid& grid, int ranks,
                             const Provenance& provenance);

// The record of a run, kept by the one process that writes it (rank 0, or
// run_explore_threads): the tiles done, in the journal, and the compressed ones it writes
// itself (from the end of the file: whatever an interrupted run wrote past its last record
// stays unused). With several writers (run/work_pool.hpp) it also records where the others
// wrote theirs and grants them their file space: whole stripes (`[run] alignment`) past
// the end, each writer its own, rank 0's share included. Every argument must outlive it.
class Recorder {
public:
    Recorder(PartialFile& file, const std::filesystem::path& partial, std::vector<std::uint8_t> done, const Job& job,
             const PartialLayout& layout, const Tiling& tiling, RunObserver& observer, int writers = 1);

    // The reports of finished tiles, with their compressed data when this process writes them.
    void done(std::span<const TileReport> tiles, std::span<const std::byte> payload);
    // Tiles another writer wrote, where they lie.
    void placed(std::span<const AppendedTile> tiles);
    // File space for a writer that asks `bytes`.
    FileSpace grant(std::uint64_t bytes);
    // The journal written, and, for compressed tiles, every tile written so far recorded
    // first and then covered by the file's HDF5 end (PlacedChunks::cover).
    void checkpoint();
    // The last tiles of a complete run: the result's figures and index come next, so the
    // journal needs no cover.
    void last();
    const Journal& journal() const { return record_; }

private:
    void recorded(std::span<const AppendedTile> tiles);
    // The observer told of tiles recorded (TileReport or AppendedTile), with their points.
    template <class Tile>
    void tell(std::span<const Tile> tiles);

    const std::filesystem::path& partial_;
    const Tiling& tiling_;
    RunObserver& observer_;
    Journal record_;
    std::uint64_t unit_ = 1;       // of file space: a stripe with several writers, else a byte
    std::uint64_t next_free_ = 0;  // the first byte no writer holds
    std::optional<ChunkAppender> appender_;
};

// A rank's compressed tiles as a batch: the payload TileWork::flush made, checked against
// the reports that came with it (std::logic_error if they differ).
TileBatch batch_of(std::span<const TileReport> tiles, std::span<const std::byte> payload);

// The buffer of a writer of uncompressed tiles (TileWriter, one a rank or thread): bytes of
// counts, at least one alignment unit and 4 MiB, so that each write is whole stripes and
// ranks rarely share one.
std::uint64_t tile_writer_bytes(const Job& job);
// Tiles handed out together (ScheduleSettings::granule): uncompressed, an alignment unit
// of tiles, so that blocks of tiles are whole stripes where they can be; compressed tiles go
// to their writer, and the granule only groups tiles for the interleaved hand-out: 1.
std::uint64_t handout_granule(const Job& job, const PartialLayout& layout);

// A run's summary before it starts: its files, its ranks, no outcome yet.
RunSummary first_summary(const ExplorePlan& plan, int ranks);

// Seconds from `t` to now.
double seconds_since(std::chrono::steady_clock::time_point t);

// A run's partial file once every process has closed it, as the one process that writes it
// (rank 0, or run_explore_threads) closes it.
struct ClosingRun {
    const Job& job;
    const Grid& grid;
    const Tiling& tiling;
    const PartialLayout& layout;
    const std::filesystem::path& partial;
    const std::filesystem::path& output;
    const Provenance& provenance;
    double earlier_seconds;  // of the runs before a resume
    std::chrono::steady_clock::time_point started;
};
// An interrupted run's seconds recorded in its partial file, or a complete run's result
// made from it (every tile done, as `done` says). Throws RunError naming the step and the
// file.
FinishReport record_or_finish(const ClosingRun& run, std::span<const std::uint8_t> done, bool interrupted,
                              RunObserver& observer);

// The refusal to resume onto a partial file whose done tiles `bad` (of `done`) no longer
// match the checksums written with them: the same words from both drivers.
InputError damaged_partial(const std::filesystem::path& partial, std::span<const std::uint64_t> bad, std::uint64_t done);

// Peak resident memory of this process, in MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib();

}  // namespace superball
