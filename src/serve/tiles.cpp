#include "tiles.hpp"

#include <png.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <nlohmann/json.hpp>
#include <utility>

#include "core/input.hpp"

namespace superball::serve {

namespace {

struct ColourMap {
    const char* name;
    std::array<Rgb, 256> lut;
};

const ColourMap colour_maps[] = {
#include "colour_maps.inc"
};

// region_map.py's fixed colours.
constexpr Rgb invalid_colour{153, 153, 153};
constexpr Rgb capped_colour{0, 0, 0};
constexpr Rgb outcome_colours[outcome_count] = {invalid_colour, {31, 119, 180}, {255, 127, 14}, capped_colour};
constexpr double map_low = 0.1, map_high = 0.95;

std::string hex(const Rgb& c)
{
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c[0], c[1], c[2]);
    return buf;
}

}  // namespace

std::vector<std::string> colour_map_names()
{
    std::vector<std::string> names;
    for (const ColourMap& m : colour_maps) names.emplace_back(m.name);
    return names;
}

Colouring parse_colouring(Query& q)
{
    Colouring c;
    c.outcome = q.choice("show", {"count", "outcome"}).value_or("count") == "outcome";
    const std::vector<std::string> names = colour_map_names();
    const std::string name = q.choice("colours", names).value_or(names[0]);
    c.map = static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    c.colour_max = static_cast<std::uint32_t>(q.integer("colour_max", 1, 4294967295, "1 to 4294967295").value_or(20));
    return c;
}

std::vector<std::string> colouring_keys() { return {"show", "colours", "colour_max"}; }

Rgb colour_of(const Colouring& c, std::uint32_t wall_bounces, Outcome outcome)
{
    if (c.outcome) return outcome_colours[static_cast<std::size_t>(outcome) % outcome_count];
    if (outcome == Outcome::invalid) return invalid_colour;
    if (outcome == Outcome::capped) return capped_colour;
    const double n = static_cast<double>(std::min(wall_bounces, c.colour_max));
    const double t = std::log1p(n) / std::log1p(static_cast<double>(c.colour_max));
    const double at = (map_low + (map_high - map_low) * t) * 255.0;
    return colour_maps[c.map].lut[static_cast<std::size_t>(std::lround(at))];
}

std::string legend_json(const Colouring& c)
{
    std::vector<std::pair<std::string, Rgb>> entries;
    if (c.outcome) {
        for (int o = 0; o < outcome_count; ++o) {
            entries.emplace_back(name(static_cast<Outcome>(o)), outcome_colours[o]);
        }
    } else {
        // Every count when there are few; else 1-2-3-5-7 steps per decade.
        std::vector<std::uint32_t> counts;
        if (c.colour_max <= 24) {
            for (std::uint32_t n = 0; n < c.colour_max; ++n) counts.push_back(n);
        } else {
            counts.push_back(0);
            for (std::uint64_t decade = 1; decade < c.colour_max; decade *= 10) {
                for (const std::uint64_t step : {1, 2, 3, 5, 7}) {
                    if (step * decade < c.colour_max) counts.push_back(static_cast<std::uint32_t>(step * decade));
                }
            }
        }
        for (const std::uint32_t n : counts) entries.emplace_back("N = " + std::to_string(n), colour_of(c, n, Outcome::left));
        entries.emplace_back("N >= " + std::to_string(c.colour_max), colour_of(c, c.colour_max, Outcome::left));
        entries.emplace_back("invalid", invalid_colour);
        entries.emplace_back("capped (N = max_bounces)", capped_colour);
    }
    nlohmann::ordered_json out = {{"colours", colour_maps[c.map].name}, {"entries", nlohmann::ordered_json::array()}};
    for (const auto& [label, colour] : entries) out["entries"].push_back({{"label", label}, {"colour", hex(colour)}});
    return out.dump() + "\n";
}

std::string tile_png(const RegionCounts& counts, const Colouring& c, std::span<const std::uint8_t> missing)
{
    const std::uint64_t w = counts.nx, h = counts.ny;
    std::vector<std::uint8_t> rgba(w * h * 4);
    for (std::uint64_t row = 0; row < h; ++row) {
        const std::uint64_t j = h - 1 - row;  // y grows upward, image rows downward
        for (std::uint64_t i = 0; i < w; ++i) {
            const std::uint64_t k = j * w + i;
            const Rgb rgb = colour_of(c, counts.wall_bounces[k], static_cast<Outcome>(counts.outcomes[k]));
            std::uint8_t* px = &rgba[(row * w + i) * 4];
            px[0] = rgb[0];
            px[1] = rgb[1];
            px[2] = rgb[2];
            px[3] = !missing.empty() && missing[k] ? 0 : 255;
        }
    }
    return encode_png(static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), rgba);
}

namespace {

// libpng's C interface around one write into a string. libpng reports errors by longjmp
// unless given an error function: this one throws, which libpng allows for C++ callers
// that do not return to it.
struct PngWriter {
    png_structp png;
    png_infop info;
    std::string out;

    PngWriter()
        : png(png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, &PngWriter::error, nullptr)),
          info(png ? png_create_info_struct(png) : nullptr)
    {
        if (!png || !info) {
            png_destroy_write_struct(&png, &info);  // either may be null
            throw std::runtime_error("libpng: cannot allocate a PNG writer");
        }
    }
    ~PngWriter() { png_destroy_write_struct(&png, &info); }
    PngWriter(const PngWriter&) = delete;
    PngWriter& operator=(const PngWriter&) = delete;

    [[noreturn]] static void error(png_structp, png_const_charp message)
    {
        throw std::runtime_error(std::string("libpng: ") + message);
    }
    static void write(png_structp p, png_bytep data, png_size_t n)
    {
        static_cast<PngWriter*>(png_get_io_ptr(p))->out.append(reinterpret_cast<const char*>(data), n);
    }
    static void flush(png_structp) {}
};

}  // namespace

std::string encode_png(std::uint32_t width, std::uint32_t height, std::span<const std::uint8_t> rgba)
{
    if (rgba.size() != std::size_t{width} * height * 4) throw std::invalid_argument("encode_png: wrong image size");
    PngWriter w;
    png_set_write_fn(w.png, &w, &PngWriter::write, &PngWriter::flush);
    // Tiles are areas of flat colour: the fastest deflate level and the Sub filter make them
    // small enough, at a small part of the time of the defaults.
    png_set_compression_level(w.png, 1);
    png_set_filter(w.png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_IHDR(w.png, w.info, width, height, 8, PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(w.png, w.info);
    for (std::uint32_t row = 0; row < height; ++row) {
        png_write_row(w.png, const_cast<png_bytep>(rgba.data() + std::size_t{row} * width * 4));
    }
    png_write_end(w.png, nullptr);
    return std::move(w.out);
}

}  // namespace superball::serve
