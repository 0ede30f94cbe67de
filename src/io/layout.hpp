// The layout of superball's files, in one place for the writers and the reader.
//
// Two kinds of file, both plain HDF5, one the other's later state:
//
//  - a *partial* file (`OUTPUT.partial`), where a run in progress keeps its tiles
//    (io/partial_file.hpp): the result's objects, one chunk per tile, and the resume
//    journal /progress (tile_done, tile_checksum, and for compressed tiles tile_stored,
//    where each lies). Compressed tiles are written past the end of the HDF5 objects and
//    not yet in the chunk index; uncompressed ones straight to their preallocated chunks;
//  - a *result* (`OUTPUT`, e.g. results/slice.h5): the partial file once every tile is
//    done, its chunks indexed where they lie, the journal removed, renamed. Laid out for
//    readers: netCDF-4/CF conventions (a coordinate variable per axis at the root,
//    attached as a dimension scale to /wall_bounces and /outcome, long_name and units on
//    every variable, flag_values/flag_meanings on /outcome), compressed (shuffle + deflate)
//    in chunks of up to 256 Ki points (the tiles), and an XDMF sidecar for ParaView.
//    An incomplete run never sits under the result's name.
//
// Both carry the same root attributes (the job, the model, the software) and coordinate
// variables; `superball_file` says which kind a file is.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace superball::layout {

// Format generation: a reader refuses other values; files of superball 0.1 had none.
// 3: partial files hold compressed tiles past their HDF5 objects (tile_stored); results
// are laid out as in format 2, which is still read.
inline constexpr std::int64_t format_version = 3;
inline constexpr std::int64_t oldest_result_format = 2;

inline constexpr const char* kind_attribute = "superball_file";
inline constexpr const char* kind_result = "result";
inline constexpr const char* kind_partial = "partial";

inline constexpr const char* wall_bounces = "/wall_bounces";
inline constexpr const char* outcome = "/outcome";
inline constexpr const char* tile_done = "/progress/tile_done";
inline constexpr const char* tile_checksum = "/progress/tile_checksum";
inline constexpr const char* tile_stored = "/progress/tile_stored";

// outcome codes, SPEC.md section 3, as CF flags.
inline constexpr std::array<std::uint8_t, 4> outcome_codes = {0, 1, 2, 3};
inline constexpr const char* outcome_meanings = "invalid left missed capped";

// Where a run in progress keeps its tiles: OUTPUT.partial.
std::filesystem::path partial_path(const std::filesystem::path& output);
// The XDMF sidecar of a result: OUTPUT with the extension .xmf.
std::filesystem::path sidecar_path(const std::filesystem::path& output);

// Descriptive attributes of a coordinate or coefficient, by name (xi, U, W, x, u, v, omega,
// e, alpha, e_wall, ...): CF long_name and units ("1" for the dimensionless).
struct VariableText {
    std::string_view long_name;
    std::string_view units;
};
VariableText variable_text(std::string_view name);

}  // namespace superball::layout
