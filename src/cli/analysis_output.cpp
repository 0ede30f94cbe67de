#include "analysis_output.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/count.hpp"

namespace superball::cli {

namespace {

using Json = nlohmann::ordered_json;

Json number(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

Json class_json(Label c, ClassRule rule)
{
    if (rule == ClassRule::count) return {{"wall_bounces", c}};
    return {{"wall_bounces", c / 4}, {"outcome", name(static_cast<Outcome>(c % 4))}};
}

std::string plus_minus(double value, double stderr_)
{
    if (!std::isfinite(value)) return "n/a (fewer than 2 scales with a boundary)";
    return std::isfinite(stderr_) ? fmt::format("{:.4f} +- {:.4f}", value, stderr_) : fmt::format("{:.4f}", value);
}

}  // namespace

void print_analysis_json(const std::string& file, const Analysis& analysis, const std::optional<Slice>& slice)
{
    const ResultPlane& plane = analysis.plane;
    const Structure& s = analysis.structure;
    const ClassRule rule = s.settings.rule;
    Json out = {{"file", file}, {"rows", s.rows}, {"cols", s.cols}, {"row_axis", plane.row_axis}, {"col_axis", plane.col_axis}};
    out["slice"] = slice ? Json{{"axis", plane.sliced_axis}, {"index", slice->index}} : Json(nullptr);
    out["cell"] = {{"row", number(plane.cell.row_cell)}, {"col", number(plane.cell.col_cell)}};
    out.update({{"classes", rule == ClassRule::count ? "count" : "count_and_outcome"}, {"tiles_missing", plane.tiles_missing}});

    const AreaFractions& a = s.area;
    Json by_outcome = Json::object();
    for (std::uint8_t o = 0; o < outcome_count; ++o) {
        by_outcome[std::string(name(static_cast<Outcome>(o)))] = {{"points", a.by_outcome[o]},
                                                                  {"fraction", number(a.outcome_fraction(o))}};
    }
    Json by_count = Json::array();
    for (std::size_t k = 0; k < a.by_count.size(); ++k) {
        by_count.push_back({{"wall_bounces", a.by_count[k].first}, {"points", a.by_count[k].second},
                            {"fraction", number(a.count_fraction(k))}});
    }
    out["area"] = {{"points", a.points}, {"valid", a.valid}, {"by_outcome", by_outcome}, {"by_count", by_count}};

    const BoundaryLength& b = s.boundary;
    Json top = Json::array();
    for (const ClassPairBoundary& p : b.top) {
        top.push_back({{"a", class_json(p.a, rule)}, {"b", class_json(p.b, rule)}, {"row_pairs", p.row_pairs},
                       {"col_pairs", p.col_pairs}, {"length", number(p.length)}});
    }
    out["boundary"] = {{"row_pairs", b.row_pairs}, {"col_pairs", b.col_pairs}, {"length", number(b.length)},
                       {"class_pairs", b.class_pairs}, {"top", top}};

    const Uncertainty& u = s.uncertainty;
    Json fraction = Json::array();
    for (std::size_t k = 0; k < u.eps.size(); ++k) fraction.push_back(number(u.fraction(k)));
    out["uncertainty"] = {{"eps", u.eps}, {"uncertain", u.uncertain}, {"valid", u.valid}, {"fraction", fraction},
                          {"exponent", number(u.exponent())}, {"exponent_stderr", number(u.fit.slope_stderr)},
                          {"dimension", number(u.dimension())}, {"fit_points", u.fit.points}};
    const BoxCounting& c = s.box_counting;
    out["box_counting"] = {{"sizes", c.sizes}, {"boxes", c.boxes}, {"dimension", number(c.dimension())},
                           {"dimension_stderr", number(c.fit.slope_stderr)}, {"fit_points", c.fit.points}};
    const BasinEntropy& e = s.basin_entropy;
    out["basin_entropy"] = {{"box", e.box}, {"boxes", e.boxes}, {"boundary_boxes", e.boundary_boxes},
                            {"S_b", number(e.entropy)}, {"S_bb", number(e.boundary_entropy)}, {"ln2", number(std::log(2.0))},
                            {"fractal_by_log2_criterion", e.fractal_by_log2_criterion()}};
    fmt::print("{}\n", out.dump(2));
}

void print_analysis_report(const std::string& file, const Analysis& analysis, const std::optional<Slice>& slice)
{
    const ResultPlane& plane = analysis.plane;
    const Structure& s = analysis.structure;
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

}  // namespace superball::cli
