#include "refine.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

namespace superball {

namespace {

// A multi-index: a fixed array, not an Extent, because the cell loops make one per cell
// and heap allocation there dominated the run (measured).
constexpr std::size_t max_axes = 4;
using Index = std::array<std::uint64_t, max_axes>;

// Points of a box addressed by multi-index, row-major.
class Layout {
public:
    explicit Layout(const Extent& shape) : dims_(shape.size())
    {
        if (dims_ > max_axes) throw std::invalid_argument("refine: too many axes");
        for (std::size_t k = 0; k < dims_; ++k) shape_[k] = shape[k];
        stride_[dims_ - 1] = 1;
        for (std::size_t k = dims_ - 1; k-- > 0;) stride_[k] = stride_[k + 1] * shape_[k + 1];
    }
    std::size_t dims() const { return dims_; }
    std::uint64_t index_step(std::size_t k) const { return stride_[k]; }
    std::uint64_t extent(std::size_t k) const { return shape_[k]; }
    std::uint64_t index(const Index& at) const
    {
        std::uint64_t i = 0;
        for (std::size_t k = 0; k < dims_; ++k) i += at[k] * stride_[k];
        return i;
    }

private:
    std::size_t dims_;
    Index shape_{};
    Index stride_{};
};

// Calls f(point) for every point of the box [lo, hi] (inclusive) whose offset from lo is
// a multiple of `step` along every axis, or lies on the upper face hi.
template <class F>
void lattice(std::size_t d, const Index& lo, const Index& hi, std::uint64_t step, F&& f)
{
    Index at = lo;
    for (;;) {
        f(at);
        std::size_t k = d;
        while (k-- > 0) {
            if (at[k] < hi[k]) {
                at[k] = std::min(at[k] + step, hi[k]);
                break;
            }
            at[k] = lo[k];
        }
        if (k == static_cast<std::size_t>(-1)) return;
    }
}

// Calls f(first, length) for every row of the box [lo, hi] (inclusive) along the last
// axis, whose points are contiguous: filling a cell row by row is a tight loop.
template <class F>
void rows(const Layout& layout, const Index& lo, const Index& hi, F&& f)
{
    const std::size_t last = layout.dims() - 1;
    Index at = lo;
    for (;;) {
        f(layout.index(at), hi[last] - lo[last] + 1);
        std::size_t k = last;
        while (k-- > 0) {
            if (at[k] < hi[k]) {
                ++at[k];
                break;
            }
            at[k] = lo[k];
        }
        if (k == static_cast<std::size_t>(-1)) return;
    }
}

// A cell: the box [a, b] (inclusive) between neighbouring lattice points.
struct Cell {
    Index a, b;
};

// The cells of the lattice of stride `step` inside `c` (offsets from c.a that are
// multiples of step, and the upper faces). An axis of one point gives flat cells.
std::vector<Cell> split(std::size_t d, const Cell& c, std::uint64_t step)
{
    std::vector<Cell> out;
    Cell at{c.a, c.a};
    for (std::size_t k = 0; k < d; ++k) at.b[k] = std::min(c.a[k] + step, c.b[k]);
    for (;;) {
        out.push_back(at);
        std::size_t k = d;
        while (k-- > 0) {
            if (at.b[k] < c.b[k]) {
                at.a[k] = at.b[k];
                at.b[k] = std::min(at.a[k] + step, c.b[k]);
                break;
            }
            at.a[k] = c.a[k];
            at.b[k] = std::min(c.a[k] + step, c.b[k]);
        }
        if (k == static_cast<std::size_t>(-1)) return out;
    }
}

enum : std::uint8_t { unknown = 0, computed = 1, filled = 2, wanted = 3 };

}  // namespace

std::uint64_t refine_tile(const Extent& shape, std::uint32_t stride, const CountPoints& count,
                          std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    const Layout layout(shape);
    const std::size_t d = layout.dims();
    std::vector<std::uint8_t> state(wall_bounces.size(), unknown);
    std::vector<std::uint64_t> need;
    std::uint64_t total = 0;

    // Computes the points listed in `need`.
    auto compute = [&] {
        std::sort(need.begin(), need.end());
        count(need);
        for (const std::uint64_t i : need) state[i] = computed;
        total += need.size();
        need.clear();
    };

    // True if the 2^d corners of the cell [a, b] hold the same count and outcome.
    auto uniform = [&](const Cell& c) {
        const std::uint64_t first = layout.index(c.a);
        std::uint64_t delta[max_axes] = {};
        for (std::size_t k = 0; k < d; ++k) delta[k] = layout.index_step(k) * (c.b[k] - c.a[k]);
        for (unsigned corner = 1; corner < (1u << d); ++corner) {
            std::uint64_t i = first;
            for (std::size_t k = 0; k < d; ++k) i += (corner >> k & 1u) ? delta[k] : 0;
            if (wall_bounces[i] != wall_bounces[first] || outcomes[i] != outcomes[first]) return false;
        }
        return true;
    };

    // The coarse lattice and its cells.
    Index lo{}, hi{};
    for (std::size_t k = 0; k < d; ++k) hi[k] = layout.extent(k) - 1;
    lattice(d, lo, hi, stride, [&](const Index& at) { need.push_back(layout.index(at)); });
    compute();
    std::vector<Cell> cells = split(d, Cell{lo, hi}, stride);

    std::vector<Cell> finer;
    std::vector<char> is_uniform;
    for (std::uint64_t s = stride; s > 1 && !cells.empty(); s /= 2) {
        const std::uint64_t half = s / 2;
        // First the cells whose corners disagree ask for their points at the next stride
        // and are split for the next level; then the others fill what no cell asked for.
        // Points on a face between the two kinds are thus computed, whatever the order of
        // the cells.
        is_uniform.assign(cells.size(), 0);
        finer.clear();
        for (std::size_t j = 0; j < cells.size(); ++j) {
            const Cell& c = cells[j];
            is_uniform[j] = static_cast<char>(uniform(c));
            if (is_uniform[j]) continue;
            lattice(d, c.a, c.b, half, [&](const Index& at) {
                const std::uint64_t i = layout.index(at);
                if (state[i] == unknown) {
                    state[i] = wanted;
                    need.push_back(i);
                }
            });
            for (const Cell& child : split(d, c, half)) finer.push_back(child);
        }
        for (std::size_t j = 0; j < cells.size(); ++j) {
            if (!is_uniform[j]) continue;
            const std::uint64_t first = layout.index(cells[j].a);
            const std::uint32_t n = wall_bounces[first];
            const std::uint8_t o = outcomes[first];
            rows(layout, cells[j].a, cells[j].b, [&](std::uint64_t i0, std::uint64_t length) {
                for (std::uint64_t i = i0; i < i0 + length; ++i) {
                    if (state[i] != unknown) continue;
                    wall_bounces[i] = n;
                    outcomes[i] = o;
                    state[i] = filled;
                }
            });
        }
        compute();
        cells.swap(finer);
    }
    return total;
}

}  // namespace superball
