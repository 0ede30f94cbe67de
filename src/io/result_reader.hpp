// The one reader of superball's files (io/layout.hpp), results and partial files alike,
// used by `info`, `analyse`, the resume decision and the viewer. Its three concerns, a file
// each: what is at a path (io/file_identity.hpp), the schema checked at open
// (io/result_schema.cpp), the values checked as they are read (io/result_reader.cpp). Results are shared
// between users and files get damaged: the reader trusts nothing. Opening validates the
// structure (objects, types, shapes, attributes and their agreement); reading validates
// the values (outcome codes, counts against max_bounces, the checksums of a partial
// file's tiles) as they pass. Every refusal is a FormatError naming the file and the
// object.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/input.hpp"
#include "file_identity.hpp"
#include "hdf5_id.hpp"
#include "job/tiles.hpp"
#include "posix_file.hpp"
#include "stored_tiles.hpp"

namespace superball {

// The file is not a valid superball file: the message names the file, the object and
// what is wrong. Bad input like a bad job (exit status 2).
struct FormatError : InputError {
    using InputError::InputError;
};

enum class FileKind { result, partial };

// What a file says about itself, validated.
struct ResultInfo {
    FileKind kind = FileKind::result;
    std::string coordinate_system;          // canonical or physical
    std::vector<std::string> axis_names;    // one per dimension of the data
    // The coordinates that are not axes, with their values, in coordinate order.
    std::vector<std::pair<std::string, double>> fixed;
    std::vector<std::uint64_t> shape;
    std::size_t count_bytes = 2;            // of /wall_bounces: 2 or 4
    std::string job_toml;
    std::string job_fingerprint;
    std::string software_version;
    std::int64_t max_bounces = 0;
    std::int64_t mpi_ranks = 0;
    // Provenance (job/provenance.hpp): CF/ACDD history (a line per run), source, date_created,
    // build; the last run's hosts and threads per rank. Empty or 0 in files written before
    // superball recorded them.
    std::string history, source, date_created, build;
    std::int64_t mpi_hosts = 0, threads = 0;
    double wall_seconds = 0;
    bool complete = false;                  // a result is complete; a partial file never is
    // Partial files: the tiling and the journal's count; results: one "tile", done.
    std::vector<std::uint64_t> tile_shape;
    std::uint64_t tiles = 1;
    std::uint64_t tiles_done = 1;

    std::uint64_t points() const;
};

// Points by outcome code, and the points not computed yet (partial files).
struct OutcomeCounts {
    std::array<std::uint64_t, 4> by_outcome{};
    std::uint64_t not_computed = 0;
};

class ResultReader {
public:
    // Opens and validates. Throws FormatError naming what is wrong: not there, not a
    // regular file, not HDF5, not a superball file, damaged (HDF5 cannot read its
    // structure), missing or contradictory objects or attributes.
    explicit ResultReader(const std::filesystem::path& path);

    const std::filesystem::path& path() const { return path_; }
    const ResultInfo& info() const { return info_; }

    // Samples of axis k: as many as the dimension, finite, strictly increasing.
    std::vector<double> axis(std::size_t k) const;

    // Partial files: the journal's done flags (0 or 1, checked at open).
    std::vector<std::uint8_t> tiles_done() const;
    // Partial files: done tiles whose data no longer match their checksums (reads them all).
    std::vector<std::uint64_t> damaged_tiles() const;

    // The values of `box` (within the data), row-major, into spans of box.points()
    // elements. Points of tiles not yet done (partial files) read as 0 bounces, outcome
    // invalid, and are counted in the return value; a done tile is checked against its
    // checksum the first time it is read. FormatError on an outcome code outside 0-3, a
    // count the outcome does not allow (invalid: 0; capped: max_bounces; others: at most
    // max_bounces), a damaged tile, or data HDF5 cannot read (naming the point or tile).
    std::uint64_t read(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const;

    // The whole file, a block of rows at a time.
    OutcomeCounts outcome_counts() const;

private:
    void validate();
    void validate_kind();
    void validate_axes();
    void validate_job_and_model();
    void validate_no_journal();
    void validate_data();
    void validate_coordinates();
    void validate_partial();
    void validate_tiles();
    void validate_journal();
    std::uint64_t read_checked(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const;
    void validate_values(const Box& box, std::span<const std::uint32_t> counts, std::span<const std::uint8_t> outcomes,
                         std::span<const std::uint8_t> computed) const;
    void load_journal() const;
    // Whether done tile t still matches its checksum.
    bool tile_intact(std::uint64_t t) const;
    // Checks every done tile that meets `box` and was not checked before.
    void verify_tiles(const Box& box) const;
    // Compressed partial files: the done tiles' values in `box`, decompressed.
    void read_stored(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const;
    // The file's bytes, for a compressed partial file's stored chunks (opened once).
    const PosixFile& raw() const;

    std::filesystem::path path_;
    h5::Id file_;
    h5::Id counts_;
    h5::Id outcomes_;
    ResultInfo info_;
    std::vector<std::uint8_t> done_;     // partial files: the journal's flags, read at open
    // Partial files: the checksums and (compressed) where each tile lies, read when a tile is
    // first read or checked (load_journal), not at open: opening a partial file to resume it
    // needs only the flags.
    mutable std::vector<std::uint64_t> sums_;
    mutable std::vector<StoredChunk> stored_;
    mutable bool journal_loaded_ = false;
    bool compressed_ = false;            // a partial file of compressed tiles
    mutable std::optional<PosixFile> raw_;
    std::optional<Tiling> tiling_;       // partial files
    // Partial files: tiles whose checksum was checked (read() is const to its callers; the
    // check is done once per tile, not once per read).
    mutable std::vector<std::uint8_t> verified_;
};

// Calls f with boxes covering a grid of `shape` once, each of at most `max_points` points
// (one point at least), in storage order: whole trailing axes where they fit.
void for_each_block(const Extent& shape, std::uint64_t max_points, const std::function<void(const Box&)>& f);

}  // namespace superball
