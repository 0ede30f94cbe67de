#include "structure.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <unordered_map>

#include "core/count.hpp"
#include "core/input.hpp"
#include "job/job.hpp"

namespace superball {

// ------------------------------------------------------------------------------ classes

namespace {

// Codes outside the format (a damaged file) are treated like invalid rather than
// indexing past the outcome table.
bool has_class(std::uint8_t outcome) { return outcome != 0 && outcome < outcome_count; }

}  // namespace

Label class_of(std::uint32_t wall_bounces, std::uint8_t outcome, ClassRule rule)
{
    if (!has_class(outcome)) return no_class;
    return rule == ClassRule::count ? wall_bounces : wall_bounces * 4 + outcome;
}

std::string describe(Label c, ClassRule rule)
{
    if (c == no_class) return "none";
    if (rule == ClassRule::count) return std::to_string(c);
    return std::to_string(c / 4) + " " + std::string(name(static_cast<Outcome>(c % 4)));
}

// ---------------------------------------------------------------------------- row source

RowSource rows_in_memory(std::span<const std::uint32_t> wall_bounces, std::span<const std::uint8_t> outcomes,
                         std::size_t rows, std::size_t cols)
{
    if (wall_bounces.size() != rows * cols || outcomes.size() != rows * cols) {
        throw std::invalid_argument("rows_in_memory: arrays do not hold rows x cols points");
    }
    RowSource src;
    src.rows = rows;
    src.cols = cols;
    src.block_rows = 7;  // deliberately not a divisor of typical sizes: exercises partial blocks
    src.read = [wall_bounces, outcomes, cols](std::size_t first, std::size_t count, std::span<std::uint32_t> wb,
                                               std::span<std::uint8_t> out) {
        std::copy_n(wall_bounces.begin() + static_cast<std::ptrdiff_t>(first * cols), count * cols, wb.begin());
        std::copy_n(outcomes.begin() + static_cast<std::ptrdiff_t>(first * cols), count * cols, out.begin());
    };
    return src;
}

// ------------------------------------------------------------------------------ line fit

LineFit fit_line(std::span<const double> x, std::span<const double> y)
{
    LineFit f;
    f.points = std::min(x.size(), y.size());
    if (f.points < 2) return f;
    const double n = static_cast<double>(f.points);
    const double mx = std::accumulate(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(f.points), 0.0) / n;
    const double my = std::accumulate(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(f.points), 0.0) / n;
    double sxx = 0, sxy = 0;
    for (std::size_t k = 0; k < f.points; ++k) {
        sxx += (x[k] - mx) * (x[k] - mx);
        sxy += (x[k] - mx) * (y[k] - my);
    }
    if (sxx == 0) return f;
    f.slope = sxy / sxx;
    f.intercept = my - f.slope * mx;
    if (f.points > 2) {
        double ss = 0;
        for (std::size_t k = 0; k < f.points; ++k) {
            const double r = y[k] - (f.slope * x[k] + f.intercept);
            ss += r * r;
        }
        f.slope_stderr = std::sqrt(ss / (n - 2) / sxx);
    }
    return f;
}

// ---------------------------------------------------------------------------- accessors

double AreaFractions::count_fraction(std::size_t k) const
{
    return valid ? static_cast<double>(by_count.at(k).second) / static_cast<double>(valid) : 0.0;
}

double AreaFractions::outcome_fraction(std::uint8_t o) const
{
    return points ? static_cast<double>(by_outcome.at(o)) / static_cast<double>(points) : 0.0;
}

double Uncertainty::fraction(std::size_t k) const
{
    return valid ? static_cast<double>(uncertain.at(k)) / static_cast<double>(valid) : 0.0;
}

bool BasinEntropy::fractal_by_log2_criterion() const { return boundary_boxes > 0 && boundary_entropy > std::log(2.0); }

std::vector<std::size_t> powers_of_two_up_to(std::size_t max)
{
    std::vector<std::size_t> v{1};
    while (v.back() <= max / 2) v.push_back(v.back() * 2);
    return v;
}

namespace {

std::size_t floor_power_of_two(std::size_t n) { return n < 1 ? 1 : powers_of_two_up_to(n).back(); }

}  // namespace

StructureSettings default_settings(std::size_t rows, std::size_t cols)
{
    StructureSettings s;
    const std::size_t side = std::min(rows, cols);
    s.eps_max = std::max<std::size_t>(2, floor_power_of_two(side / 64));
    s.box_max = floor_power_of_two(std::max<std::size_t>(1, side / 16));
    return s;
}

// ---------------------------------------------------------------------------- estimators

namespace {

// A pair of points on either side of a boundary: both have a class, and they differ.
inline std::uint8_t differ(Label a, Label b)
{
    return static_cast<std::uint8_t>((a != b) & (a != no_class) & (b != no_class));
}

// The last `depth` rows of class labels, row i in slot i % depth.
class Window {
public:
    Window(std::size_t cols, std::size_t depth) : cols_(cols), depth_(depth), labels_(cols * depth) {}

    std::span<Label> slot(std::size_t i) { return {labels_.data() + (i % depth_) * cols_, cols_}; }
    std::span<const Label> row(std::size_t i) const { return {labels_.data() + (i % depth_) * cols_, cols_}; }

private:
    std::size_t cols_;
    std::size_t depth_;
    std::vector<Label> labels_;
};

class AreaCounter {
public:
    void add(std::span<const std::uint32_t> wall_bounces, std::span<const std::uint8_t> outcomes)
    {
        for (std::size_t k = 0; k < outcomes.size(); ++k) {
            const std::uint8_t o = has_class(outcomes[k]) ? outcomes[k] : 0;
            ++by_outcome_[o];
            if (o == 0) continue;
            const std::uint32_t n = wall_bounces[k];
            // Dense table for the counts that occur in practice, a map for the rare huge ones.
            if (n < dense_limit) {
                if (n >= dense_.size()) dense_.resize(n + 1, 0);
                ++dense_[n];
            } else {
                ++sparse_[n];
            }
        }
    }

    AreaFractions result() const
    {
        AreaFractions a;
        a.by_outcome = by_outcome_;
        a.points = std::accumulate(by_outcome_.begin(), by_outcome_.end(), std::uint64_t{0});
        a.valid = a.points - by_outcome_[0];
        for (std::size_t n = 0; n < dense_.size(); ++n) {
            if (dense_[n]) a.by_count.emplace_back(static_cast<std::uint32_t>(n), dense_[n]);
        }
        for (const auto& [n, c] : sparse_) a.by_count.emplace_back(n, c);
        return a;
    }

private:
    static constexpr std::uint32_t dense_limit = 1u << 20;
    std::array<std::uint64_t, 4> by_outcome_{};
    std::vector<std::uint64_t> dense_;
    std::map<std::uint32_t, std::uint64_t> sparse_;
};

class BoundaryCounter {
public:
    BoundaryCounter(CellSize cell, std::size_t top) : cell_(cell), top_(top) {}

    // Pairs (i, j), (i, j+1) within `row`.
    void add_row(std::span<const Label> row)
    {
        for (std::size_t j = 0; j + 1 < row.size(); ++j) {
            if (differ(row[j], row[j + 1])) add_pair(row[j], row[j + 1], 0);
        }
    }

    // Pairs (i, j), (i+1, j) between consecutive rows.
    void add_rows(std::span<const Label> above, std::span<const Label> row)
    {
        for (std::size_t j = 0; j < row.size(); ++j) {
            if (differ(above[j], row[j])) add_pair(above[j], row[j], 1);
        }
    }

    BoundaryLength result() const
    {
        BoundaryLength b;
        std::vector<ClassPairBoundary> all;
        all.reserve(pairs_.size());
        for (const auto& [key, n] : pairs_) {
            ClassPairBoundary p;
            p.a = static_cast<Label>(key >> 32);
            p.b = static_cast<Label>(key & 0xffffffffu);
            p.row_pairs = n[0];
            p.col_pairs = n[1];
            p.length = length(n[0], n[1]);
            b.row_pairs += n[0];
            b.col_pairs += n[1];
            all.push_back(p);
        }
        b.length = length(b.row_pairs, b.col_pairs);
        b.class_pairs = all.size();
        // Ties broken by the classes, so the report does not depend on hash order.
        const auto longer = [](const ClassPairBoundary& x, const ClassPairBoundary& y) {
            const auto nx = x.row_pairs + x.col_pairs, ny = y.row_pairs + y.col_pairs;
            if (x.length != y.length) return x.length > y.length;
            if (nx != ny) return nx > ny;
            return std::pair(x.a, x.b) < std::pair(y.a, y.b);
        };
        const std::size_t keep = std::min(top_, all.size());
        std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(keep), all.end(), longer);
        b.top.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(keep));
        return b;
    }

private:
    void add_pair(Label x, Label y, int along)
    {
        const auto key = (std::uint64_t{std::min(x, y)} << 32) | std::max(x, y);
        ++pairs_[key][static_cast<std::size_t>(along)];
    }

    double length(std::uint64_t row_pairs, std::uint64_t col_pairs) const
    {
        return static_cast<double>(row_pairs) * cell_.row_cell + static_cast<double>(col_pairs) * cell_.col_cell;
    }

    CellSize cell_;
    std::size_t top_;
    std::unordered_map<std::uint64_t, std::array<std::uint64_t, 2>> pairs_;
};

// Distance from each point to the nearest point of another class along its row or its
// column, for the points of one row once the h rows after it are in; a histogram of the
// distances up to h. f(e) is then the share of distances <= e, for every e at once.
//
// Along a line (a row, or one column over the rows) the points form runs of one class
// (points without a class do not interrupt a run). A point's nearest other class before
// it is the end of the previous run, or the previous point with a class when that one
// starts a new run; after it, the start of the next run, known when that run starts:
// the points of the ending run within h of it are settled then. Each point is settled
// once per direction, so a row costs O(cols) whatever h.
class UncertaintyCounter {
public:
    UncertaintyCounter(std::size_t cols, std::size_t h)
        : cols_(cols), h_(h), distance_((h + 1) * cols), row_distance_(cols), columns_(cols), histogram_(h + 1, 0)
    {
    }

    // Row r of labels; rows come in order. Settles row r - h.
    void add(std::size_t r, std::span<const Label> row)
    {
        const auto d = slot(r);
        std::fill(row_distance_.begin(), row_distance_.end(), far);
        Run along_row;
        for (std::size_t j = 0; j < cols_; ++j) {
            if (row[j] == no_class) {
                row_distance_[j] = none;
                continue;
            }
            const std::uint32_t before = step(along_row, j, row[j], [&](std::size_t from, std::size_t to) {
                for (std::size_t p = from; p < to; ++p) settle(row_distance_[p], j - p);
            });
            settle(row_distance_[j], before);
        }
        for (std::size_t j = 0; j < cols_; ++j) {
            d[j] = row_distance_[j];
            if (row[j] == no_class) continue;
            const std::uint32_t before = step(columns_[j], r, row[j], [&](std::size_t from, std::size_t to) {
                for (std::size_t p = from; p < to; ++p) settle(slot(p)[j], r - p);
            });
            settle(d[j], before);
        }
        if (r >= h_) count(r - h_);
    }

    // After the last row: settles the rows not yet settled.
    void finish(std::size_t rows)
    {
        for (std::size_t c = rows > h_ ? rows - h_ : 0; c < rows; ++c) count(c);
    }

    std::uint64_t valid() const { return valid_; }
    // Points with a class whose nearest other class is at most e away.
    std::uint64_t within(std::size_t e) const
    {
        const auto end = histogram_.begin() + static_cast<std::ptrdiff_t>(std::min(e, h_) + 1);
        return std::accumulate(histogram_.begin(), end, std::uint64_t{0});
    }

private:
    static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();  // no class
    static constexpr std::uint32_t far = none - 1;                                     // nothing within h

    struct Run {
        Label label = no_class;
        std::size_t start = 0;
        std::optional<std::size_t> last;      // last point with a class
        std::optional<std::size_t> prev_end;  // last point of the run before this one
    };

    // Point `pos` of class `c` on a line: returns the distance to the nearest point of
    // another class before it (far if none within h) and settles, through
    // `settle_ended(from, to)`, the points [from, to) of the run it ends.
    template <class Settle>
    std::uint32_t step(Run& run, std::size_t pos, Label c, Settle&& settle_ended) const
    {
        std::optional<std::size_t> other;
        if (c != run.label) {
            if (run.label != no_class) settle_ended(std::max(run.start, pos > h_ ? pos - h_ : 0), pos);
            other = run.last;
            run.prev_end = run.last;
            run.label = c;
            run.start = pos;
        } else {
            other = run.prev_end;
        }
        run.last = pos;
        return other && pos - *other <= h_ ? static_cast<std::uint32_t>(pos - *other) : far;
    }

    static void settle(std::uint32_t& d, std::size_t candidate)
    {
        if (d != none && candidate < d) d = static_cast<std::uint32_t>(candidate);
    }

    std::span<std::uint32_t> slot(std::size_t r) { return {distance_.data() + (r % (h_ + 1)) * cols_, cols_}; }

    void count(std::size_t r)
    {
        for (const std::uint32_t d : slot(r)) {
            if (d == none) continue;
            ++valid_;
            if (d <= h_) ++histogram_[d];
        }
    }

    std::size_t cols_;
    std::size_t h_;
    std::vector<std::uint32_t> distance_;      // rows r - h .. r, row i in slot i % (h + 1)
    std::vector<std::uint32_t> row_distance_;  // along the row being added
    std::vector<Run> columns_;                 // the run state of each column
    std::vector<std::uint64_t> histogram_;     // [d]: settled points whose nearest other class is d away
    std::uint64_t valid_ = 0;
};

// Sets mask[j] = 1 where point j of `row` is the second point (in row or column order) of
// an adjacent pair of different classes: row[j - 1] or above[j] (the previous row, empty
// for the first) differs. Each boundary edge between two cells is marked once, on the
// cell after it: a half-open box [a, a + s) meets the edge at coordinate j exactly when
// it holds cell j.
void mark_boundary_edges(std::span<const Label> above, std::span<const Label> row, std::span<std::uint8_t> mask)
{
    const std::size_t n = row.size();
    if (n == 0) return;
    mask[0] = 0;
    for (std::size_t j = 1; j < n; ++j) mask[j] = differ(row[j - 1], row[j]);
    if (!above.empty()) {
        for (std::size_t j = 0; j < n; ++j) mask[j] |= differ(above[j], row[j]);
    }
}

// N(s) for s = 2^k: per level, which boxes of the current band of rows hold a boundary
// point. Level k is built from level k-1 (a box of side 2s covers 2 x 2 boxes of side s),
// so a row costs about 2 cols whatever the number of levels.
class BoxCounter {
public:
    BoxCounter(std::size_t rows, std::size_t cols, std::size_t max_size)
        : rows_(rows), sizes_(powers_of_two_up_to(max_size)), boxes_(sizes_.size(), 0)
    {
        for (const std::size_t s : sizes_) {
            row_marks_.emplace_back((cols + s - 1) / s, std::uint8_t{0});
            band_marks_.emplace_back((cols + s - 1) / s, std::uint8_t{0});
        }
    }

    // `boundary`: 1 at the cells of row i that hold a boundary edge.
    void add(std::size_t i, std::span<const std::uint8_t> boundary)
    {
        std::copy(boundary.begin(), boundary.end(), row_marks_[0].begin());
        for (std::size_t k = 1; k < sizes_.size(); ++k) {
            const auto& fine = row_marks_[k - 1];
            auto& coarse = row_marks_[k];
            for (std::size_t j = 0; j < coarse.size(); ++j) {
                coarse[j] = fine[2 * j] | (2 * j + 1 < fine.size() ? fine[2 * j + 1] : std::uint8_t{0});
            }
        }
        for (std::size_t k = 0; k < sizes_.size(); ++k) {
            auto& band = band_marks_[k];
            const auto& marks = row_marks_[k];
            for (std::size_t j = 0; j < band.size(); ++j) band[j] |= marks[j];
            if ((i + 1) % sizes_[k] == 0 || i + 1 == rows_) {
                boxes_[k] += static_cast<std::uint64_t>(std::count(band.begin(), band.end(), std::uint8_t{1}));
                std::fill(band.begin(), band.end(), std::uint8_t{0});
            }
        }
    }

    BoxCounting result() const
    {
        BoxCounting b;
        b.sizes = sizes_;
        b.boxes = boxes_;
        std::vector<double> x, y;
        for (std::size_t k = 0; k < sizes_.size(); ++k) {
            if (boxes_[k] == 0) continue;
            x.push_back(-std::log(static_cast<double>(sizes_[k])));
            y.push_back(std::log(static_cast<double>(boxes_[k])));
        }
        b.fit = fit_line(x, y);
        return b;
    }

private:
    std::size_t rows_;
    std::vector<std::size_t> sizes_;
    std::vector<std::uint64_t> boxes_;
    std::vector<std::vector<std::uint8_t>> row_marks_;
    std::vector<std::vector<std::uint8_t>> band_marks_;
};

class EntropyCounter {
public:
    EntropyCounter(std::size_t cols, std::size_t box) : cols_(cols), box_(box) { labels_.reserve(box * box); }

    // The band of rows last-box+1 .. last, all in `w`.
    void add_band(const Window& w, std::size_t last)
    {
        for (std::size_t j0 = 0; j0 + box_ <= cols_; j0 += box_) {
            labels_.clear();
            for (std::size_t i = last + 1 - box_; i <= last; ++i) {
                const auto row = w.row(i).subspan(j0, box_);
                for (const Label c : row) {
                    if (c != no_class) labels_.push_back(c);
                }
            }
            if (labels_.empty()) continue;
            ++boxes_;
            // Most boxes lie inside one region: no sort needed to see that.
            if (std::all_of(labels_.begin(), labels_.end(), [&](Label c) { return c == labels_.front(); })) continue;
            std::sort(labels_.begin(), labels_.end());
            double s = 0;
            const double total = static_cast<double>(labels_.size());
            for (auto it = labels_.begin(); it != labels_.end();) {
                const auto next = std::upper_bound(it, labels_.end(), *it);
                const double p = static_cast<double>(next - it) / total;
                s -= p * std::log(p);
                it = next;
            }
            ++boundary_boxes_;
            entropy_sum_ += s;
        }
    }

    BasinEntropy result() const
    {
        BasinEntropy b;
        b.box = box_;
        b.boxes = boxes_;
        b.boundary_boxes = boundary_boxes_;
        b.entropy = boxes_ ? entropy_sum_ / static_cast<double>(boxes_) : 0.0;
        b.boundary_entropy = boundary_boxes_ ? entropy_sum_ / static_cast<double>(boundary_boxes_) : 0.0;
        return b;
    }

private:
    std::size_t cols_;
    std::size_t box_;
    std::vector<Label> labels_;
    std::uint64_t boxes_ = 0;
    std::uint64_t boundary_boxes_ = 0;
    double entropy_sum_ = 0;  // uniform boxes add 0
};

struct Wanted {
    bool area = false, boundary = false, uncertainty = false, boxes = false, entropy = false;
};

// The single pass. Row r is labelled and pushed into the window as it is read; boundary
// pairs and box counting look back one row, basin entropy handles a band of `box` rows
// once its last row is in, and uncertainty settles row r - h (h = the largest distance
// looked at) with its own window of distances.
Structure run(const RowSource& src, const StructureSettings& settings, Wanted want)
{
    if (!src.read) throw std::invalid_argument("RowSource without a reader");
    if (want.entropy && settings.entropy_box < 1) throw std::invalid_argument("basin entropy box size must be >= 1");
    const std::size_t rows = src.rows, cols = src.cols;
    const std::vector<std::size_t> eps =
        want.uncertainty ? powers_of_two_up_to(std::max<std::size_t>(1, settings.eps_max)) : std::vector<std::size_t>{};
    const std::size_t h = want.uncertainty ? eps.back() : 0;
    const std::size_t depth = std::max(want.entropy ? settings.entropy_box : 1, std::size_t{2});

    Window window(cols, depth);
    AreaCounter area;
    BoundaryCounter boundary(settings.cell, settings.top_pairs);
    UncertaintyCounter uncertain(want.uncertainty ? cols : 0, h);
    BoxCounter boxes(rows, cols, want.boxes ? std::max<std::size_t>(1, settings.box_max) : 1);
    EntropyCounter entropy(cols, std::max<std::size_t>(1, settings.entropy_box));
    std::vector<std::uint8_t> edges(cols);

    const std::size_t block = std::max<std::size_t>(1, src.block_rows);
    std::vector<std::uint32_t> wall_bounces;
    std::vector<std::uint8_t> outcomes;
    for (std::size_t first = 0; first < rows; first += block) {
        const std::size_t count = std::min(block, rows - first);
        wall_bounces.resize(count * cols);
        outcomes.resize(count * cols);
        src.read(first, count, wall_bounces, outcomes);
        if (want.area) area.add(wall_bounces, outcomes);
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t r = first + k;
            const auto slot = window.slot(r);
            for (std::size_t j = 0; j < cols; ++j) {
                slot[j] = class_of(wall_bounces[k * cols + j], outcomes[k * cols + j], settings.rule);
            }
            if (want.boundary) {
                boundary.add_row(window.row(r));
                if (r > 0) boundary.add_rows(window.row(r - 1), window.row(r));
            }
            if (want.boxes) {
                mark_boundary_edges(r > 0 ? window.row(r - 1) : std::span<const Label>{}, window.row(r), edges);
                boxes.add(r, edges);
            }
            if (want.entropy && (r + 1) % settings.entropy_box == 0) entropy.add_band(window, r);
            if (want.uncertainty) uncertain.add(r, window.row(r));
        }
    }
    if (want.uncertainty) uncertain.finish(rows);

    Structure s;
    s.rows = rows;
    s.cols = cols;
    s.settings = settings;
    if (want.area) s.area = area.result();
    if (want.boundary) s.boundary = boundary.result();
    if (want.uncertainty) {
        Uncertainty& u = s.uncertainty;
        u.eps = eps;
        for (const std::size_t e : eps) u.uncertain.push_back(uncertain.within(e));
        u.valid = uncertain.valid();
        std::vector<double> x, y;
        for (std::size_t k = 0; k < eps.size(); ++k) {
            if (u.uncertain[k] == 0) continue;  // log 0: no boundary within e says nothing
            x.push_back(std::log(static_cast<double>(eps[k])));
            y.push_back(std::log(u.fraction(k)));
        }
        u.fit = fit_line(x, y);
    }
    if (want.boxes) s.box_counting = boxes.result();
    if (want.entropy) s.basin_entropy = entropy.result();
    return s;
}

}  // namespace

AreaFractions area_fractions(const RowSource& src)
{
    Wanted w;
    w.area = true;
    return run(src, StructureSettings{}, w).area;
}

BoundaryLength boundary_length(const RowSource& src, ClassRule rule, CellSize cell, std::size_t top)
{
    StructureSettings s;
    s.rule = rule;
    s.cell = cell;
    s.top_pairs = top;
    Wanted w;
    w.boundary = true;
    return run(src, s, w).boundary;
}

Uncertainty uncertainty(const RowSource& src, ClassRule rule, std::size_t eps_max)
{
    StructureSettings s;
    s.rule = rule;
    s.eps_max = eps_max;
    Wanted w;
    w.uncertainty = true;
    return run(src, s, w).uncertainty;
}

BoxCounting box_counting(const RowSource& src, ClassRule rule, std::size_t max_size)
{
    StructureSettings s;
    s.rule = rule;
    s.box_max = max_size;
    Wanted w;
    w.boxes = true;
    return run(src, s, w).box_counting;
}

BasinEntropy basin_entropy(const RowSource& src, ClassRule rule, std::size_t box)
{
    StructureSettings s;
    s.rule = rule;
    s.entropy_box = box;
    Wanted w;
    w.entropy = true;
    return run(src, s, w).basin_entropy;
}

Structure analyse_structure(const RowSource& src, const StructureSettings& settings)
{
    return run(src, settings, Wanted{true, true, true, true, true});
}

}  // namespace superball
