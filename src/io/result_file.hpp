// The result file of an exploration (SPEC.md section 5), written in parallel through
// MPI-IO.
//
// Crash safety: every dataset is created with all its chunks allocated and the file is
// flushed before any tile is computed, so from then on the file's metadata never
// changes until the end of the run. A tile's data is written (pwrite through MPI-IO)
// before its byte in /progress/tile_done, so a process killed at any moment leaves a
// readable file in which every tile marked done holds its final data. A checksum of the
// tile's values, written between the two, lets a resume refuse a file whose done tiles
// were changed on disk since (damaged_tiles).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "job/grid.hpp"
#include "job/job.hpp"
#include "mpi/mpi.hpp"
#include "job/tiles.hpp"
#include "hdf5.hpp"

namespace superball {

// A fast 64-bit checksum of one tile's values, written to /progress/tile_checksum with
// them. Not cryptographic: it catches bytes changed on disk, not a forgery. Any change
// confined to one 64-bit word of the stream (counts two to a word, then outcomes eight to
// a word) always changes it, every step being a bijection of its lane; four lanes keep
// the multiplications out of one dependency chain (0.55 ns a point on the 2-core test
// machine, build/release/tests/bench/bench_io; 1.0 ns with the lanes in an array). Its values are part of the file format: files written
// before a change would read as damaged.
std::uint64_t tile_checksum(std::uint64_t tile, std::span<const std::uint32_t> counts,
                            std::span<const std::uint8_t> outcomes);

// Tiles whose data no longer match the checksum written with them (/progress/
// tile_checksum): bytes changed on disk after the tile was marked done. Read without MPI
// (rank 0 before a resume). Empty when every done tile checks out, or for a file written
// before checksums existed (nothing to compare).
std::vector<std::uint64_t> damaged_tiles(const std::filesystem::path& path);

// What a result file says about itself, read without MPI (rank 0 deciding whether to
// resume, `superball info`).
struct ResultInfo {
    std::string coordinates;
    std::vector<std::string> axis_names;
    std::vector<std::uint64_t> shape;
    std::vector<std::uint64_t> tile_shape;
    std::string job_toml;
    std::string job_fingerprint;
    std::string software_version;
    std::int64_t max_bounces = 0;
    std::int64_t mpi_ranks = 0;
    double wall_seconds = 0;
    bool complete = false;
    std::uint64_t tiles = 0;
    std::uint64_t tiles_done = 0;
};

// Throws h5::Error if the file cannot be read as a superball result.
ResultInfo read_result_info(const std::filesystem::path& path);

// Outcome histogram of the whole file, read a block of rows at a time (serial).
std::vector<std::uint64_t> outcome_histogram(const std::filesystem::path& path);

class ResultFile {
public:
    // Collective: creates (or truncates) `path` with datasets, axes and attributes.
    static ResultFile create(const std::filesystem::path& path, const mpi::Comm& comm, const Job& job, const Grid& grid,
                             const Tiling& tiling);
    // Collective: reopens a result for resume. Checking that it belongs to the job is the
    // caller's business (read_result_info), done before.
    static ResultFile open(const std::filesystem::path& path, const mpi::Comm& comm);

    // Closing is collective (H5Fclose of a parallel file). Destroyed by an exception on
    // this rank alone, the file is not closed but let go: the caller ends every rank
    // (MPI_Abort), and the file stays as the last tile left it, resumable. (Closing here
    // waited for ranks that were still computing: a full disk hung the run.)
    ~ResultFile();
    ResultFile(ResultFile&&) noexcept = default;
    ResultFile& operator=(ResultFile&&) noexcept = default;

    const Tiling& tiling() const { return tiling_; }
    // Done flags of all tiles (independent read; every rank may call it).
    std::vector<std::uint8_t> tiles_done() const;

    // Independent: one tile's data, its checksum, then its done flag. A failed write
    // throws h5::Error saying which tile and file, and how full the file system is.
    void write_tile(std::uint64_t tile, std::span<const std::uint32_t> wall_bounces,
                    std::span<const std::uint8_t> outcomes);

    // Collective: run attributes, then close.
    void finish(double run_seconds, int ranks, bool complete);

private:
    ResultFile(h5::Id file, Tiling tiling, std::filesystem::path path);

    h5::Id file_;
    h5::Id wall_bounces_;
    h5::Id outcome_;
    h5::Id tile_done_;
    h5::Id tile_checksum_;  // not valid in files written before checksums existed
    Tiling tiling_;
    std::filesystem::path path_;
    // uint16 counts are narrowed here, not by HDF5: its conversion path allocates and
    // zeroes a buffer on every write (measured 6% of a run).
    bool narrow_counts_ = false;
    std::vector<std::uint16_t> narrow_;
};

}  // namespace superball
