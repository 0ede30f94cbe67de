#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "core/count.hpp"
#include "core/input.hpp"
#include "io/hdf5.hpp"
#include "io/result_plane.hpp"

namespace superball::cli {

namespace {

struct AnalyseOptions {
    std::string file;
    std::string slice;
    std::size_t box = 5;
    std::optional<std::size_t> eps_max;
    std::optional<std::size_t> box_max;
    std::size_t top = 5;
    bool with_outcome = false;
    bool json = false;
};

// "AXIS=INDEX", e.g. "U=0" or "1=0".
Slice parse_slice(const std::string& text)
{
    const auto eq = text.find('=');
    const std::string index = eq == std::string::npos ? "" : text.substr(eq + 1);
    if (eq == 0 || index.empty() || index.find_first_not_of("0123456789") != std::string::npos || index.size() > 18) {
        throw InputError("--slice: expected AXIS=INDEX (an axis name or number and a sample index, e.g. U=0), got '" +
                         text + "'");
    }
    return {text.substr(0, eq), std::stoull(index)};
}

// JSON has no NaN: an estimate that could not be made is null.
std::string json_number(double x) { return std::isfinite(x) ? fmt::format("{}", x) : "null"; }

std::string json_class(Label c, ClassRule rule)
{
    if (rule == ClassRule::count) return fmt::format("{{\"wall_bounces\": {}}}", c);
    return fmt::format("{{\"wall_bounces\": {}, \"outcome\": \"{}\"}}", c / 4, name(static_cast<Outcome>(c % 4)));
}

template <class T>
std::string json_array(const std::vector<T>& v)
{
    std::string s = "[";
    for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + fmt::format("{}", v[k]);
    return s + "]";
}

std::string plus_minus(double value, double stderr_)
{
    if (!std::isfinite(value)) return "n/a (fewer than 2 scales with a boundary)";
    return std::isfinite(stderr_) ? fmt::format("{:.4f} +- {:.4f}", value, stderr_) : fmt::format("{:.4f}", value);
}

void print_json(const std::string& file, const ResultPlane& plane, const std::optional<Slice>& slice, const Structure& s)
{
    const ClassRule rule = s.settings.rule;
    fmt::print("{{\n");
    fmt::print("  \"file\": {},\n", quote(file));
    fmt::print("  \"rows\": {}, \"cols\": {}, \"row_axis\": {}, \"col_axis\": {},\n", s.rows, s.cols,
               quote(plane.row_axis), quote(plane.col_axis));
    if (slice) {
        fmt::print("  \"slice\": {{\"axis\": {}, \"index\": {}}},\n", quote(plane.sliced_axis), slice->index);
    } else {
        fmt::print("  \"slice\": null,\n");
    }
    fmt::print("  \"cell\": {{\"row\": {}, \"col\": {}}},\n", json_number(plane.cell.row_cell), json_number(plane.cell.col_cell));
    fmt::print("  \"classes\": \"{}\",\n", rule == ClassRule::count ? "count" : "count_and_outcome");
    fmt::print("  \"tiles_missing\": {},\n", plane.tiles_missing);

    const AreaFractions& a = s.area;
    fmt::print("  \"area\": {{\n    \"points\": {}, \"valid\": {},\n    \"by_outcome\": {{", a.points, a.valid);
    for (std::uint8_t o = 0; o < outcome_count; ++o) {
        fmt::print("{}\"{}\": {{\"points\": {}, \"fraction\": {}}}", o ? ", " : "", name(static_cast<Outcome>(o)),
                   a.by_outcome[o], json_number(a.outcome_fraction(o)));
    }
    fmt::print("}},\n    \"by_count\": [");
    for (std::size_t k = 0; k < a.by_count.size(); ++k) {
        fmt::print("{}\n      {{\"wall_bounces\": {}, \"points\": {}, \"fraction\": {}}}", k ? "," : "", a.by_count[k].first,
                   a.by_count[k].second, json_number(a.count_fraction(k)));
    }
    fmt::print("\n    ]\n  }},\n");

    const BoundaryLength& b = s.boundary;
    fmt::print("  \"boundary\": {{\"row_pairs\": {}, \"col_pairs\": {}, \"length\": {}, \"class_pairs\": {}, \"top\": [",
               b.row_pairs, b.col_pairs, json_number(b.length), b.class_pairs);
    for (std::size_t k = 0; k < b.top.size(); ++k) {
        const ClassPairBoundary& p = b.top[k];
        fmt::print("{}\n    {{\"a\": {}, \"b\": {}, \"row_pairs\": {}, \"col_pairs\": {}, \"length\": {}}}", k ? "," : "",
                   json_class(p.a, rule), json_class(p.b, rule), p.row_pairs, p.col_pairs, json_number(p.length));
    }
    fmt::print("]}},\n");

    const Uncertainty& u = s.uncertainty;
    std::vector<std::string> f;
    for (std::size_t k = 0; k < u.eps.size(); ++k) f.push_back(json_number(u.fraction(k)));
    fmt::print("  \"uncertainty\": {{\"eps\": {}, \"uncertain\": {}, \"valid\": {}, \"fraction\": {},\n", json_array(u.eps),
               json_array(u.uncertain), u.valid, json_array(f));
    fmt::print("    \"exponent\": {}, \"exponent_stderr\": {}, \"dimension\": {}, \"fit_points\": {}}},\n",
               json_number(u.exponent()), json_number(u.fit.slope_stderr), json_number(u.dimension()), u.fit.points);

    const BoxCounting& c = s.box_counting;
    fmt::print("  \"box_counting\": {{\"sizes\": {}, \"boxes\": {}, \"dimension\": {}, \"dimension_stderr\": {}, "
               "\"fit_points\": {}}},\n",
               json_array(c.sizes), json_array(c.boxes), json_number(c.dimension()), json_number(c.fit.slope_stderr),
               c.fit.points);

    const BasinEntropy& e = s.basin_entropy;
    fmt::print("  \"basin_entropy\": {{\"box\": {}, \"boxes\": {}, \"boundary_boxes\": {}, \"S_b\": {}, \"S_bb\": {}, "
               "\"ln2\": {}, \"fractal_by_log2_criterion\": {}}}\n",
               e.box, e.boxes, e.boundary_boxes, json_number(e.entropy), json_number(e.boundary_entropy),
               json_number(std::log(2.0)), e.fractal_by_log2_criterion() ? "true" : "false");
    fmt::print("}}\n");
}

void print_report(const std::string& file, const ResultPlane& plane, const std::optional<Slice>& slice, const Structure& s)
{
    const ClassRule rule = s.settings.rule;
    fmt::print("file:     {}\n", file);
    fmt::print("plane:    {} {} (rows) x {} {} (columns){}\n", s.rows, plane.row_axis, s.cols, plane.col_axis,
               slice ? fmt::format(", slice {} = {}", plane.sliced_axis, slice->index) : "");
    fmt::print("cells:    {:.6g} x {:.6g} (axis units)\n", plane.cell.row_cell, plane.cell.col_cell);
    fmt::print("classes:  {}; invalid points belong to no class\n",
               rule == ClassRule::count ? "wall-bounce count" : "wall-bounce count and outcome");
    if (plane.tiles_missing) fmt::print("note:     {} tiles not yet computed, read as invalid\n", plane.tiles_missing);

    const AreaFractions& a = s.area;
    fmt::print("\nArea fractions: outcomes (of {} points)\n", a.points);
    for (std::uint8_t o = 0; o < outcome_count; ++o) {
        fmt::print("  {:<8} {:>14} {:10.6f}\n", name(static_cast<Outcome>(o)), a.by_outcome[o], a.outcome_fraction(o));
    }
    fmt::print("Area fractions: wall bounces (of {} points with a class)\n", a.valid);
    // The largest areas; --json lists every count.
    std::vector<std::size_t> order(a.by_count.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t x, std::size_t y) { return a.by_count[x].second > a.by_count[y].second; });
    const std::size_t shown = std::min<std::size_t>(order.size(), 15);
    std::sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown));
    fmt::print("  {:>8} {:>14} {:>10}\n", "N", "points", "fraction");
    for (std::size_t k = 0; k < shown; ++k) {
        fmt::print("  {:>8} {:>14} {:10.6f}\n", a.by_count[order[k]].first, a.by_count[order[k]].second,
                   a.count_fraction(order[k]));
    }
    if (shown < order.size()) fmt::print("  ... {} smaller counts not shown (see --json)\n", order.size() - shown);

    const BoundaryLength& b = s.boundary;
    fmt::print("\nBoundary length (adjacent pairs of different class)\n");
    fmt::print("  pairs along rows {}, along columns {}; length {:.6g} (axis units), {} pairs of classes touch\n",
               b.row_pairs, b.col_pairs, b.length, b.class_pairs);
    if (!b.top.empty()) fmt::print("  {:>14} {:>14} {:>12} {:>12} {:>12}\n", "class a", "class b", "row pairs", "col pairs", "length");
    for (const ClassPairBoundary& p : b.top) {
        fmt::print("  {:>14} {:>14} {:>12} {:>12} {:>12.6g}\n", describe(p.a, rule), describe(p.b, rule), p.row_pairs,
                   p.col_pairs, p.length);
    }

    const Uncertainty& u = s.uncertainty;
    fmt::print("\nUncertainty: f(e) = fraction of points with another class within e cells along their row or column\n");
    fmt::print("  {:>6} {:>14} {:>12}\n", "e", "uncertain", "f(e)");
    for (std::size_t k = 0; k < u.eps.size(); ++k) fmt::print("  {:>6} {:>14} {:12.6g}\n", u.eps[k], u.uncertain[k], u.fraction(k));
    fmt::print("  uncertainty exponent alpha = {}\n", plus_minus(u.exponent(), u.fit.slope_stderr));
    fmt::print("  boundary dimension D = 2 - alpha = {}\n", plus_minus(u.dimension(), u.fit.slope_stderr));

    const BoxCounting& c = s.box_counting;
    fmt::print("\nBox counting: N(s) = boxes of s x s cells that meet the boundary (edges between cells of different class)\n");
    fmt::print("  {:>6} {:>14}\n", "s", "N(s)");
    for (std::size_t k = 0; k < c.sizes.size(); ++k) fmt::print("  {:>6} {:>14}\n", c.sizes[k], c.boxes[k]);
    fmt::print("  box-counting dimension D = {}\n", plus_minus(c.dimension(), c.fit.slope_stderr));

    const BasinEntropy& e = s.basin_entropy;
    fmt::print("\nBasin entropy (boxes of {} x {} points)\n", e.box, e.box);
    fmt::print("  N_b  = {:<12} S_b  = {:.6f}\n", e.boxes, e.entropy);
    fmt::print("  N_bb = {:<12} S_bb = {:.6f}\n", e.boundary_boxes, e.boundary_entropy);
    if (e.fractal_by_log2_criterion()) {
        fmt::print("  S_bb > ln 2 = {:.6f}: the boundary is fractal (sufficient condition)\n", std::log(2.0));
    } else {
        fmt::print("  S_bb <= ln 2 = {:.6f}: the log 2 criterion is not met (it is sufficient, not necessary)\n",
                   std::log(2.0));
    }
}

}  // namespace

Runner add_analyse_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("analyse", "Structure of the regions of a 2-D result: areas, boundaries, fractal dimension, "
                                              "basin entropy");
    sub->footer(
        "The class of a point is its wall-bounce count (with --with-outcome: count and outcome);\n"
        "points with outcome invalid belong to no class. Reports area fractions, the length of\n"
        "the boundaries between classes, the uncertainty exponent alpha (the fraction of points with\n"
        "another class within e cells along their row or column ~ e^alpha) and D = 2 - alpha, the\n"
        "box-counting dimension of the boundary, and the basin entropy S_b, S_bb (Daza et al. 2016).\n"
        "The file is read a band of rows at a time: memory grows with the row length, not the grid.\n"
        "Example: superball analyse results/quickstart.h5 --json");
    auto opt = std::make_shared<AnalyseOptions>();
    sub->add_option("file", opt->file, "result file (.h5) written by superball explore")->required();
    sub->add_option("--slice", opt->slice, "the plane of a 3-D result: AXIS=INDEX, e.g. U=0 (required for 3-D results)");
    sub->add_option("--box", opt->box, "side of the basin-entropy boxes, in points")
        ->check(CLI::Range(std::size_t{1}, std::size_t{4096}))
        ->capture_default_str();
    sub->add_option("--eps-max", opt->eps_max,
                    "largest distance e (cells) for the uncertainty exponent; e = 1, 2, 4, ... up to it "
                    "(default: min(rows, cols)/64, at least 2)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--box-max", opt->box_max,
                    "largest box side s (cells) for box counting; s = 1, 2, 4, ... up to it (default: min(rows, cols)/16)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--top", opt->top, "pairs of classes listed by boundary length")->capture_default_str();
    sub->add_flag("--with-outcome", opt->with_outcome, "classes are (count, outcome) pairs, not counts alone");
    sub->add_flag("--json", opt->json, "print a JSON object instead of a report");
    return [opt] {
        h5::silence_errors();
        const ClassRule rule = opt->with_outcome ? ClassRule::count_and_outcome : ClassRule::count;
        const std::optional<Slice> slice = opt->slice.empty() ? std::nullopt : std::optional(parse_slice(opt->slice));
        const ResultPlane plane = open_result_plane(opt->file, slice, rule);
        const std::size_t rows = plane.source.rows, cols = plane.source.cols;

        StructureSettings settings = default_settings(rows, cols);
        settings.rule = rule;
        settings.cell = plane.cell;
        settings.entropy_box = opt->box;
        settings.top_pairs = opt->top;
        if (opt->eps_max) settings.eps_max = *opt->eps_max;
        if (opt->box_max) settings.box_max = *opt->box_max;
        // The window holds 2 eps_max + 1 rows: beyond the grid it would only cost memory.
        if (settings.eps_max >= std::max(rows, cols)) {
            throw InputError(fmt::format("--eps-max {} is not smaller than the grid ({} x {})", settings.eps_max, rows, cols));
        }
        if (settings.box_max > std::max(rows, cols)) {
            throw InputError(fmt::format("--box-max {} is larger than the grid ({} x {})", settings.box_max, rows, cols));
        }
        if (settings.entropy_box > std::min(rows, cols)) {
            throw InputError(fmt::format("--box {} is larger than the grid ({} x {}): no box fits", settings.entropy_box, rows,
                                         cols));
        }
        const Structure s = analyse_structure(plane.source, settings);
        if (opt->json) {
            print_json(opt->file, plane, slice, s);
        } else {
            print_report(opt->file, plane, slice, s);
        }
        return 0;
    };
}

}  // namespace superball::cli
