// Job files (SPEC.md section 4): what grid to explore, with which model, and where the
// result goes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/input.hpp"
#include "core/model.hpp"
#include "core/state.hpp"

namespace superball {

// The limits of a job, which a result file read back must meet too (io/result_schema.cpp).
// 2^40 points is 1 TiB of counts at one byte each: beyond that a typo is more likely than
// an intent, and uint64 index arithmetic stays far from overflow.
inline constexpr std::uint64_t max_grid_points = std::uint64_t{1} << 40;
// Counts are stored as uint32.
inline constexpr std::int64_t max_max_bounces = std::numeric_limits<std::uint32_t>::max();

enum class Coordinates { canonical, physical };

constexpr std::string_view name(Coordinates c) { return c == Coordinates::canonical ? "canonical" : "physical"; }

// Names of the coordinates, in the order of result-file dimensions (SPEC.md section 5).
std::vector<std::string> coordinate_names(Coordinates c);  // {"xi","U","W"} or {"x","u","v","omega"}

// n cell-centred samples of [min, max].
struct Range {
    double min = 0.0;
    double max = 0.0;
    std::uint64_t n = 0;

    // Sample i = min + (i + 0.5) (max - min) / n: cell centres, so the singular planes
    // at the ends of a range are never sampled exactly. The one place this is computed.
    double sample(std::uint64_t i) const { return min + (static_cast<double>(i) + 0.5) * (max - min) / static_cast<double>(n); }

    friend bool operator==(const Range&, const Range&) = default;
};

// One coordinate of the grid: a fixed value or a range.
struct Coordinate {
    std::string name;
    std::optional<double> fixed;  // set iff `range` is not
    std::optional<Range> range;

    bool is_range() const { return range.has_value(); }
    friend bool operator==(const Coordinate&, const Coordinate&) = default;
};

// The model coefficients a job may sweep as range axes, in the order their axes come in
// results (before the coordinates): e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, and
// SPEC.md 1b's mu, mu_wall, mu_floor, inertia.
std::vector<std::string> coefficient_names();
// The model's own coefficients, one value each (what `Job::swept` and a result's attributes
// hold): e_wall, alpha_wall, e_floor, alpha_floor, mu_wall, mu_floor, inertia.
std::vector<std::string> model_coefficient_names();
inline constexpr std::size_t swept_coefficients = model_coefficient_count;  // core/model.hpp's model_coefficients()
// SPEC.md 1b's coefficients (mu, mu_wall, mu_floor, inertia): results hold them only where
// they are not their defaults, and files written before them have none.
bool is_friction_coefficient(std::string_view name);

struct Job {
    Model model{};  // swept coefficients hold their range's min here (see model_at)
    Coordinates coordinates = Coordinates::canonical;
    Frame frame{};                        // g and radius: physical grids only
    std::vector<Coordinate> grid;         // every coordinate, in coordinate_names() order
    // Model coefficients given as ranges in [model], in coefficient_names() order.
    std::vector<Coordinate> parameters;
    // For each of model_coefficient_names(): the index in `parameters` of the axis that sets
    // it, or -1 when it is fixed (per-surface keys override e, alpha and mu).
    std::array<int, swept_coefficients> swept{-1, -1, -1, -1, -1, -1, -1};
    std::uint32_t max_bounces = 1000;
    std::string output;                   // [run] output, as written (may be empty: then the CLI must be given one)
    std::optional<std::uint64_t> tile_points;  // [run] tile_points: target points per tile
    // [run] refine: 0 computes every point; a power of two s computes every s-th point
    // and subdivides only the cells whose corners disagree (explore/refine.hpp).
    std::uint32_t refine = 0;
    // How the result is written; none of these changes a single count, so none is part of
    // the fingerprint. [run] compression: deflate level of the final result (0: none).
    int compression = 4;
    // [run] alignment: large objects of the files (the data of each dataset) start at a
    // multiple of this many bytes, and ranks write in multiples of it where they can: the
    // stripe size of a Lustre or GPFS file system.
    std::uint64_t alignment = std::uint64_t{1} << 20;
    // [run] checkpoint_seconds: rank 0 records the finished tiles (the resume journal) at
    // most this often, and when the run ends or stops.
    double checkpoint_seconds = 10.0;
    // [run] writers: the processes that write compressed tiles, rank 0 and node leaders (at
    // most one per node; run/work_pool.hpp); 0 ("auto"): one per node from 64 ranks on,
    // else rank 0 alone.
    std::uint32_t writers = 0;
    std::string text;                     // the job file's text, stored in results

    // The range axes, in result order: swept parameters, then coordinates (1 to 4 in all).
    std::vector<const Coordinate*> range_axes() const;
    // The model at given values of the swept parameters (one per entry of `parameters`).
    Model model_at(std::span<const double> parameter_values) const;
    // Number of grid points (product of the range sizes).
    std::uint64_t points() const;
};

// The most writers a job may ask for ([run] writers, explore --writers).
inline constexpr std::uint32_t max_writers = 65536;
// "auto" (0) or a count of writers from 1 to max_writers, as written after `key` (the
// flag or key named by the InputError otherwise).
std::uint32_t writers_from_text(std::string_view text, std::string_view key);

// Parses and validates a job. `source` names the text in messages (usually the path).
// Throws InputError naming the key, the value and what is accepted.
Job parse_job(std::string_view text, std::string_view source);

// Reads and parses a job file; a missing or unreadable file is an InputError too.
Job load_job(const std::filesystem::path& path);

// A canonical text of everything that determines the results (coordinates, grid, model,
// g/radius, max_bounces) and nothing else (not the output path, comments or key order).
// Resume refuses a file whose fingerprint differs.
std::string fingerprint(const Job& job);

}  // namespace superball
