// A 2-D plane of a result file for the basin measures (`superball analyse`), read a block
// of rows at a time.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "measures/structure.hpp"

namespace superball {

// Which plane of a 3-D result: `index` along the axis named `axis` (or numbered: "0",
// "1", "2").
struct Slice {
    std::string axis;
    std::uint64_t index = 0;
};

// A 2-D plane of a result file, read a block of rows at a time.
struct ResultPlane {
    std::string row_axis, col_axis;  // names of the first and second axis of the plane
    std::string sliced_axis;         // empty for a 2-D result
    CellSize cell;                   // spacing of the samples along each
    std::uint64_t tiles_missing = 0; // tiles not yet computed: their points read as invalid
    std::int64_t max_bounces = 0;
    RowSource source;                // keeps the file open while it lives
};

// Opens the plane of `path`: a 2-D result (slice must be empty) or the slice of a 3-D
// one (slice required). Throws InputError naming the problem (not a result, 1-D, missing
// or bad slice), h5::Error on I/O failure.
ResultPlane open_result_plane(const std::filesystem::path& path, std::optional<Slice> slice, ClassRule rule);

}  // namespace superball
