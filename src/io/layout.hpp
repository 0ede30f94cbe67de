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
#include <vector>

namespace superball::layout {

// Format generation: a reader refuses other values; files of superball 0.1 had none.
// 3: partial files hold compressed tiles past their HDF5 objects (tile_stored); results
// are laid out as in format 2, which is still read.
inline constexpr std::int64_t format_version = 3;
inline constexpr std::int64_t oldest_result_format = 2;

// The attributes of a file, each name and type written once here and used by the writers
// (result_metadata.cpp, partial_file.cpp, final_result.cpp) and the reader
// (result_reader.cpp). Text: fixed-length ASCII (netCDF's NC_CHAR, for CF's descriptive
// attributes); std::string: a variable-length string.
struct Text {};
template <class T>
struct Attribute {
    const char* name;
    operator std::string() const { return name; }  // where only the name is wanted
};
namespace attr {
// At the root of both kinds of file.
inline constexpr Attribute<std::string> kind{"superball_file"};  // kind_result or kind_partial
inline constexpr Attribute<std::int64_t> format{"superball_format"};  // format_version
inline constexpr Attribute<Text> conventions{"Conventions"};
inline constexpr Attribute<Text> title{"title"};
inline constexpr Attribute<Text> source{"source"};
inline constexpr Attribute<Text> date_created{"date_created"};
inline constexpr Attribute<Text> build{"build"};
inline constexpr Attribute<std::string> coordinate_system{"coordinate_system"};  // canonical or physical
inline constexpr Attribute<std::vector<std::string>> axis_names{"axis_names"};
inline constexpr const char* fixed_prefix = "fixed_";  // fixed_<coordinate>: double
inline constexpr Attribute<std::vector<std::string>> swept{"swept"};
inline constexpr Attribute<double> g{"g"};  // physical grids
inline constexpr Attribute<double> radius{"radius"};
inline constexpr Attribute<std::int64_t> max_bounces{"max_bounces"};
inline constexpr Attribute<std::int64_t> refine{"refine"};
inline constexpr Attribute<std::string> job_toml{"job_toml"};
inline constexpr Attribute<std::string> job_fingerprint{"job_fingerprint"};
inline constexpr Attribute<std::string> software_version{"software_version"};
inline constexpr Attribute<std::string> history{"history"};
inline constexpr Attribute<std::int64_t> mpi_ranks{"mpi_ranks"};
inline constexpr Attribute<std::int64_t> mpi_hosts{"mpi_hosts"};
inline constexpr Attribute<std::int64_t> threads{"threads"};
inline constexpr Attribute<double> wall_seconds{"wall_seconds"};
inline constexpr Attribute<std::int64_t> complete{"complete"};  // 0 or 1
// A partial file's only (the tiling its journal is of).
inline constexpr Attribute<std::vector<std::uint64_t>> tile_shape{"tile_shape"};
// On the variables (CF).
inline constexpr Attribute<Text> long_name{"long_name"};
inline constexpr Attribute<Text> units{"units"};
inline constexpr Attribute<Text> coordinates{"coordinates"};
inline constexpr Attribute<std::vector<std::uint8_t>> flag_values{"flag_values"};
inline constexpr Attribute<Text> flag_meanings{"flag_meanings"};
}  // namespace attr

inline constexpr const char* kind_attribute = attr::kind.name;
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
