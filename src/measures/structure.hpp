// The structure of the regions of a 2-D field of wall-bounce counts (`superball analyse`):
// area fractions, boundary length, uncertainty exponent, box-counting dimension of the
// boundary, basin entropy.
//
// Everything is computed in one pass over the rows, in order, keeping only sliding
// windows: the block of rows being read, the last max(2, entropy box) rows of classes and
// the distances of the last eps_max + 1 rows. Memory is a row times a few hundred, never
// the whole array (8192^2: 30 MB, 16384^2: 48 MB). The field comes from a RowSource: a
// result file (open_result_plane) or, in tests, an array in memory (rows_in_memory).
//
// Terms used throughout (row i, column j; rows run along the first axis of the plane):
//
//  - The *class* of a point is its wall-bounce count N (ClassRule::count, the default),
//    or the pair (N, outcome) (ClassRule::count_and_outcome), which also separates
//    "left after N" from "missed after N". Points whose outcome is `invalid` have no
//    class: they are counted in the outcome fractions and nowhere else, and a pair with
//    one of them is never a boundary.
//  - Points (i, j +- 1) and (i +- 1, j) are *adjacent* to (i, j).
//  - A point is *e-uncertain* if a point of another class lies within e cells of it along
//    its row or its column: one of (i, j +- d), (i +- d, j), 1 <= d <= e (Grebogi,
//    McDonald, Ott, Yorke 1983: a perturbation of the launch by at most e along an axis can
//    change its outcome). Points off the grid do not exist. Looking at every d up to e,
//    not only at d = e, keeps f(e) monotone and sees thin regions (a line of one class one
//    cell wide is not jumped over).
//  - A *boundary pair* is a pair of adjacent points of different classes; the boundary
//    is drawn as the edges between the cells of such pairs (box counting, item 4).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace superball {

// ------------------------------------------------------------------------------ classes

using Label = std::uint32_t;
inline constexpr Label no_class = std::numeric_limits<Label>::max();  // outcome invalid

enum class ClassRule { count, count_and_outcome };

// The class of a point. count_and_outcome packs N*4 + outcome, so it requires
// N < 2^30 - 1; count requires N < 2^32 - 1 (checked by open_result_plane).
Label class_of(std::uint32_t wall_bounces, std::uint8_t outcome, ClassRule rule);

// "12" or "12 left": a class the way a report shows it.
std::string describe(Label c, ClassRule rule);

// ---------------------------------------------------------------------------- row source

// A rows x cols field of (wall bounces, outcome), delivered a block of rows at a time.
struct RowSource {
    // Fills `wall_bounces` and `outcomes` (row-major, size count*cols) with rows
    // [first, first + count).
    using Reader = std::function<void(std::size_t first, std::size_t count, std::span<std::uint32_t> wall_bounces,
                                      std::span<std::uint8_t> outcomes)>;

    std::size_t rows = 0;
    std::size_t cols = 0;
    std::size_t block_rows = 64;  // rows per read: the file's tile height reads each chunk once
    Reader read;
};

// A source over arrays held by the caller (they must outlive it). For tests and small fields.
RowSource rows_in_memory(std::span<const std::uint32_t> wall_bounces, std::span<const std::uint8_t> outcomes,
                         std::size_t rows, std::size_t cols);

// ---------------------------------------------------------------------------- estimators

// Least-squares line y = slope x + intercept, with the standard error of the slope
// (NaN with fewer than 3 points, where residuals say nothing).
struct LineFit {
    double slope = std::numeric_limits<double>::quiet_NaN();
    double intercept = std::numeric_limits<double>::quiet_NaN();
    double slope_stderr = std::numeric_limits<double>::quiet_NaN();
    std::size_t points = 0;
};
LineFit fit_line(std::span<const double> x, std::span<const double> y);

// 1. Area fractions. Per count: among points with a class (outcome not invalid); per
// outcome: among all points. Both sum to 1 (when there are such points).
struct AreaFractions {
    std::uint64_t points = 0;
    std::uint64_t valid = 0;  // points whose outcome is not invalid
    std::vector<std::pair<std::uint32_t, std::uint64_t>> by_count;  // (N, points), N ascending, nonzero only
    std::array<std::uint64_t, 4> by_outcome{};                    // indexed by outcome code

    double count_fraction(std::size_t k) const;     // of by_count[k]
    double outcome_fraction(std::uint8_t o) const;
};
AreaFractions area_fractions(const RowSource& src);

// 2. Boundary length. An adjacent pair of different classes contributes the cell side
// perpendicular to it: a pair along a row ((i,j), (i,j+1)) is separated by a segment of
// length row_cell (the cell size along the first axis), a pair along a column by col_cell.
struct CellSize {
    double row_cell = 1.0;  // extent of a cell along the first axis (between rows)
    double col_cell = 1.0;  // along the second axis (between columns)
};
struct ClassPairBoundary {
    Label a = 0, b = 0;  // a < b
    std::uint64_t row_pairs = 0;  // differing pairs along rows (neighbours (i,j), (i,j+1))
    std::uint64_t col_pairs = 0;  // along columns ((i,j), (i+1,j))
    double length = 0;
};
struct BoundaryLength {
    std::uint64_t row_pairs = 0;
    std::uint64_t col_pairs = 0;
    double length = 0;                    // in axis units: row_pairs*row_cell + col_pairs*col_cell
    std::uint64_t class_pairs = 0;        // distinct pairs of classes that touch
    std::vector<ClassPairBoundary> top;   // the longest, longest first
};
BoundaryLength boundary_length(const RowSource& src, ClassRule rule, CellSize cell, std::size_t top = 5);

// 3. Uncertainty exponent: f(e) = (e-uncertain points) / (points with a class) for
// e = 1, 2, 4, ..., eps_max; fit log f = alpha log e + c over the e with f > 0. alpha is
// the uncertainty exponent and D = 2 - alpha the box-counting dimension of the boundary
// (McDonald, Grebogi, Ott, Yorke 1985). The pass keeps the distances of eps_max + 1 rows.
struct Uncertainty {
    std::vector<std::size_t> eps;
    std::vector<std::uint64_t> uncertain;
    std::uint64_t valid = 0;
    LineFit fit;

    double fraction(std::size_t k) const;
    double exponent() const { return fit.slope; }
    double dimension() const { return 2.0 - fit.slope; }
};
Uncertainty uncertainty(const RowSource& src, ClassRule rule, std::size_t eps_max);

// 4. Box-counting dimension of the boundary. Cell (i, j) is the unit square
// [i, i+1) x [j, j+1); the boundary is the union of the unit edges between adjacent cells
// of different classes, each edge half-open like the cells. The grid is tiled into boxes
// [a s, (a+1) s) x [b s, (b+1) s) from (0, 0) (boxes at the far edges may be cut short);
// N(s) counts the boxes that meet the boundary. In terms of points: a box counts if it
// holds the second point (in row or column order) of an adjacent pair of different
// classes, the first point lying in the same box or in the one before it. Marking one
// side only keeps the boundary one cell thick, so a straight boundary gives N(s) ~ 1/s
// from s = 1 on. Fit log N(s) = D log(1/s) + c; s = 1, 2, 4, ..., max_size.
struct BoxCounting {
    std::vector<std::size_t> sizes;
    std::vector<std::uint64_t> boxes;
    LineFit fit;

    double dimension() const { return fit.slope; }
};
BoxCounting box_counting(const RowSource& src, ClassRule rule, std::size_t max_size);

// 5. Basin entropy (Daza, Wagemakers, Georgeot, Guery-Odelin, Sanjuan 2016, Sci. Rep. 6,
// 31416). The grid is tiled into boxes of n x n points from (0, 0); boxes cut short by
// the far edges are left out so that every box weighs the same. A box's entropy is the
// Gibbs entropy -sum p_k ln p_k of the class frequencies p_k among its points with a
// class; boxes without any are left out. S_b is the mean over the N_b boxes, S_bb the
// mean over the N_bb boxes holding more than one class. S_bb > ln 2 is a sufficient (not
// necessary) condition for a fractal boundary.
struct BasinEntropy {
    std::size_t box = 0;
    std::uint64_t boxes = 0;           // N_b
    std::uint64_t boundary_boxes = 0;  // N_bb
    double entropy = 0;                // S_b
    double boundary_entropy = 0;       // S_bb (0 if N_bb = 0)

    bool fractal_by_log2_criterion() const;
};
BasinEntropy basin_entropy(const RowSource& src, ClassRule rule, std::size_t box = 5);

// ----------------------------------------------------------------------- all in one pass

struct StructureSettings {
    ClassRule rule = ClassRule::count;
    CellSize cell{};
    std::size_t entropy_box = 5;
    std::size_t eps_max = 1;       // uncertainty at e = 1, 2, 4, ..., eps_max
    std::size_t box_max = 1;       // box counting at s = 1, 2, 4, ..., box_max
    std::size_t top_pairs = 5;
};

// Defaults scaled to the grid: eps_max = min(rows, cols)/64 (at least 2) and box_max = min(rows, cols)/16, both powers of two, so that
// the fits span the scales from the cell to well below the grid.
StructureSettings default_settings(std::size_t rows, std::size_t cols);

// 1, 2, 4, ... up to max (at least {1}).
std::vector<std::size_t> powers_of_two_up_to(std::size_t max);

struct Structure {
    std::size_t rows = 0, cols = 0;
    StructureSettings settings;
    AreaFractions area;
    BoundaryLength boundary;
    Uncertainty uncertainty;
    BoxCounting box_counting;
    BasinEntropy basin_entropy;
};

// Every estimator in a single pass over the rows.
Structure analyse_structure(const RowSource& src, const StructureSettings& settings);

}  // namespace superball
