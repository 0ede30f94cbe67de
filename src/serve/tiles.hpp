// Map tiles: counts and outcomes coloured as analysis/region_map.py colours them, encoded
// as PNG (libpng), and the legend of a colouring.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "query.hpp"
#include "region.hpp"

namespace superball::serve {

using Rgb = std::array<std::uint8_t, 3>;

// The colour maps tiles can use (matplotlib's, colour_maps.inc); the first is the default.
std::vector<std::string> colour_map_names();

struct Colouring {
    std::size_t map = 0;             // index into colour_map_names()
    std::uint32_t colour_max = 20;   // counts from here up share the top colour
    bool outcome = false;            // colour by outcome instead of count
};

// show=count|outcome, colours=NAME, colour_max=N (1 to 2^32 - 1).
Colouring parse_colouring(Query& q);
std::vector<std::string> colouring_keys();  // show, colours, colour_max

// A count N of a launch that left or missed lies at log(1 + N) / log(1 + colour_max) of the
// way along the colour map, clipped at 1, within the part 0.1-0.95 of the map that
// region_map.py uses (its ends could pass for the invalid grey or the capped black).
// Invalid launches are grey and capped ones black in every colouring; outcomes have
// region_map.py's colours.
Rgb colour_of(const Colouring& c, std::uint32_t wall_bounces, Outcome outcome);

// The legend: {"entries": [{"label": "N = 0", "colour": "#rrggbb"}, ...]} for counts (each
// count below colour_max, or a geometric selection when there are many, then
// "N >= colour_max", invalid, capped) or the four outcomes.
std::string legend_json(const Colouring& c);

// RGBA PNG of a view's counts, x across and y up (the first image row is the last sample
// of y). Points with `missing[k]` set are transparent.
std::string tile_png(const RegionCounts& counts, const Colouring& c, std::span<const std::uint8_t> missing = {});

// PNG of a width x height image, 4 bytes a pixel, row-major from the top.
std::string encode_png(std::uint32_t width, std::uint32_t height, std::span<const std::uint8_t> rgba);

}  // namespace superball::serve
