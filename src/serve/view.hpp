// What the API's requests ask for: a model, a start point, a region of a plane of the
// canonical coordinates, a map tile of one; read from a Query with the command line's
// and the job file's wording, and written back as a job file.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/input.hpp"
#include "job/job.hpp"
#include "query.hpp"

namespace superball::serve {

// What one request may cost. Regions beyond `region_points` are refused with 413 (a job
// for `superball explore` is the way to larger grids); max_bounces is bounded so that a
// block of work stays short enough to cancel (the command line takes up to 2^32 - 1).
struct Limits {
    std::uint64_t region_points = std::uint64_t{1} << 20;
    std::uint32_t max_bounces = 1000000;
    std::uint32_t trajectory_bounces = 10000;   // wall impacts in one trajectory answer
    std::uint64_t trajectory_points = 1000000;  // path samples in one trajectory answer
};

// The canonical coordinates, in the order of results: xi, U, W.
inline constexpr std::array<std::string_view, 3> axis_names{"xi", "U", "W"};

// Two axes drawn (x across, y up) and the third held fixed; indices into axis_names.
struct Plane {
    int x = 0;
    int y = 2;
    int fixed = 1;
};

// A region of a plane: the samples along x and y (cell centres, Range::sample) at a fixed
// value of the third coordinate, under one model.
struct View {
    Plane plane;
    Range x;
    Range y;
    double fixed = 0;
    ModelInput model_input;  // as given, for the job file
    Model model;
    std::uint32_t max_bounces = 1000;
};

ModelInput parse_model_input(Query& q);
Model parse_model(Query& q, ModelInput& input);
// Default 1000, as on the command line.
std::uint32_t parse_max_bounces(Query& q, std::uint32_t limit);
// xi, U, W or x, u, v, omega (g, radius): resolve_start() with the API's spelling.
Start parse_start(Query& q);

// x, y, the fixed coordinate, the model and max_bounces; x_min, x_max, y_min, y_max; nx and
// ny when `sizes` (regions, jobs), else 1 (tile windows: see tile_view).
View parse_view(Query& q, const Limits& limits, bool sizes);

// Tile (z, tx, ty) of a map whose zoom-0 tile is `window` (x across, y up; tile rows go
// down from the window's top): `n` samples per side of the window's 2^-z part. Throws
// RequestError when double precision cannot tell the samples apart.
View tile_view(const View& window, int z, std::int64_t tx, std::int64_t ty, std::uint64_t n);

// The view as a job file for `superball explore` (output = `output`, left out if empty);
// `comment` (lines beginning with "# ": the export's provenance) after the header.
std::string job_toml(const View& v, std::string_view output, std::string_view comment = {});

// The job of job_toml(v, ""), parsed by parse_job: what explore would compute for v.
Job job_of(const View& v);

}  // namespace superball::serve
