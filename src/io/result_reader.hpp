// The one reader of superball's files (io/layout.hpp), results and partial files alike,
// used by `info`, `analyse`, the resume decision and the viewer. Results are shared
// between users and files get damaged: the reader trusts nothing. Opening validates the
// structure (objects, types, shapes, attributes and their agreement); reading validates
// the values (outcome codes, counts within max_bounces) as they pass.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/input.hpp"
#include "hdf5.hpp"
#include "job/tiles.hpp"

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
    // Opens and validates. Throws FormatError naming what is wrong (not HDF5, not a
    // superball file, missing or contradictory objects or attributes), h5::Error when the
    // file cannot be read at all.
    explicit ResultReader(const std::filesystem::path& path);

    const std::filesystem::path& path() const { return path_; }
    const ResultInfo& info() const { return info_; }

    // Samples of axis k: as many as the dimension, finite, strictly monotonic.
    std::vector<double> axis(std::size_t k) const;

    // Partial files: the journal (FormatError on a flag other than 0 or 1).
    std::vector<std::uint8_t> tiles_done() const;
    std::vector<std::uint64_t> tile_checksums() const;
    // Partial files: done tiles whose data no longer match their checksums (reads them all).
    std::vector<std::uint64_t> damaged_tiles() const;

    // The values of `box`, row-major. Points of tiles not yet done (partial files) read as
    // 0 bounces, outcome invalid, and are counted in the return value. FormatError on an
    // outcome code outside 0-3 or a count above max_bounces.
    std::uint64_t read(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const;

    // The whole file, a block of rows at a time.
    OutcomeCounts outcome_counts() const;

private:
    void validate();
    std::uint64_t read_checked(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const;
    void validate_values(const Box& box, std::span<const std::uint32_t> counts, std::span<const std::uint8_t> outcomes,
                         std::span<const std::uint8_t> computed) const;

    std::filesystem::path path_;
    h5::Id file_;
    h5::Id counts_;
    h5::Id outcomes_;
    ResultInfo info_;
    std::vector<std::uint8_t> done_;  // partial files: the journal, read once
};

// Kind of thing at `path`, for messages that say what a non-result is: "a directory", "a
// text file", "an HDF5 file that is not a superball result", ...
std::string describe_file(const std::filesystem::path& path);

}  // namespace superball
