#include "count_simd.hpp"

#include <algorithm>
#include <array>
#include <experimental/simd>
#include <limits>

namespace superball {

namespace {

namespace stdx = std::experimental;
// One register of the build's widest vector unit: 2 lanes with SSE2 (the portable
// build), 4 with AVX2. (fixed_size_simd<double, 8> was measured 3.7x slower per lane
// with GCC 12: its generic implementation does not keep the lanes in registers.)
using Batch = stdx::native_simd<double>;
constexpr std::size_t width = Batch::size();

// Points are taken a block at a time; the block's live points are kept packed at the
// front of structure-of-arrays buffers.
constexpr std::size_t block = 512;

// Exit codes as doubles, so that they are computed with vector selects: an Outcome, or
// go_on for a point that needs another excursion.
constexpr double go_on = -1.0;
constexpr double code(Outcome o) { return static_cast<double>(o); }

struct Live {
    // Padded by one batch so the last, partial batch can be loaded and stored whole.
    alignas(64) std::array<double, block + width> xi, U, W, n;
    std::array<std::size_t, block + width> point;
    std::size_t size = 0;
};

// What one application of G made of a batch of points: the new state, the new count and
// the exit code.
struct Stepped {
    alignas(64) std::array<double, block + width> xi, U, W, n, code;
};

// Where the results of the points go.
struct Results {
    std::span<std::uint32_t> wall_bounces;
    std::span<std::uint8_t> outcomes;
};

// G applied to a batch: the exits of SPEC.md section 3 after the step, in the order
// count() checks them (invalid takes precedence over left over missed over capped).
[[gnu::always_inline]] inline void step(const CanonicalState<Batch>& c, const Batch& count, const ModelMatrices& m, double max_bounces,
          Stepped& next, std::size_t i)
{
    const CanonicalStep<Batch> s = canonical_map(c, m);
    Batch exit = go_on;
    stdx::where(count >= max_bounces, exit) = code(Outcome::capped);
    stdx::where(!(s.next.xi < 1.0), exit) = code(Outcome::missed);
    stdx::where(s.next.U >= 0.0, exit) = code(Outcome::left);
    // Overflow or division by zero (map.hpp, representable): invalid with 0 impacts, as
    // count() says, before everything else.
    const auto lost = !representable(s);
    stdx::where(lost, exit) = code(Outcome::invalid);
    Batch n = count;
    stdx::where(lost, n) = 0.0;
    s.next.xi.copy_to(&next.xi[i], stdx::vector_aligned);
    s.next.U.copy_to(&next.U[i], stdx::vector_aligned);
    s.next.W.copy_to(&next.W[i], stdx::vector_aligned);
    n.copy_to(&next.n[i], stdx::vector_aligned);
    exit.copy_to(&next.code[i], stdx::vector_aligned);
}

// Stores the points that ended and packs the others at the front of `live` (in place:
// a point never moves up). This is the lane refill: the next sweep's batches are full
// of live points, however long some of them live. Neighbouring points of a grid mostly
// end alike, so the branch is well predicted (measured faster than storing every point
// every step without a branch).
void settle(const Stepped& next, std::size_t n, const std::size_t* point, Live& live, const Results& out)
{
    // Locals, not members: a store through the uint8_t outcomes may alias anything, and
    // would make the compiler reload every pointer and the size after it.
    std::uint32_t* const wall_bounces = out.wall_bounces.data();
    std::uint8_t* const outcomes = out.outcomes.data();
    std::size_t size = live.size;
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t p = point[i];
        if (next.code[i] != go_on) {
            wall_bounces[p] = static_cast<std::uint32_t>(next.n[i]);
            outcomes[p] = static_cast<std::uint8_t>(next.code[i]);
            continue;
        }
        live.xi[size] = next.xi[i];
        live.U[size] = next.U[i];
        live.W[size] = next.W[i];
        live.n[size] = next.n[i];
        live.point[size] = p;
        ++size;
    }
    live.size = size;
}

// The first excursion of a block, read straight from the input: the checks count()
// makes before any excursion (not a launch, missing at once) are vector compares too.
// Two passes, the arithmetic alone over all batches and then the bookkeeping point by
// point: kept apart, each loop is short enough for the processor to overlap many
// batches; interleaved, every batch waited on its own divisions and square root.
void first_sweep(const StartsView& in, const ModelMatrices& m, double max_bounces, Stepped& next, Live& live,
                 std::array<std::size_t, block + width>& index, const Results& out, std::size_t first)
{
    const std::size_t n = in.size();
    for (std::size_t i = 0; i < n; i += width) {
        // The last batch may be partial: its missing lanes get a harmless launch.
        auto lane = [&](std::span<const double> x, double pad) {
            return Batch([&](auto l) { return i + l < n ? x[i + l] : pad; });
        };
        const CanonicalState<Batch> c = i + width <= n
                                            ? CanonicalState<Batch>{Batch(&in.xi[i], stdx::element_aligned),
                                                                    Batch(&in.U[i], stdx::element_aligned),
                                                                    Batch(&in.W[i], stdx::element_aligned)}
                                            : CanonicalState<Batch>{lane(in.xi, 0.5), lane(in.U, -1.0), lane(in.W, 0.0)};
        step(c, Batch(1.0), m, max_bounces, next, i);
        Batch before = go_on;  // decided before any excursion, with 0 impacts
        stdx::where(!(c.xi < 1.0), before) = code(Outcome::missed);
        // is_launch() as plain compares (NaN fails each): finite xi > 0, finite U < 0, finite W.
        constexpr double inf = std::numeric_limits<double>::infinity();
        const auto launch = c.xi > 0.0 && c.xi < inf && c.U < 0.0 && c.U > -inf && stdx::abs(c.W) < inf;
        stdx::where(!launch, before) = code(Outcome::invalid);
        const auto decided = before != go_on;
        Batch exit(&next.code[i], stdx::vector_aligned), count(&next.n[i], stdx::vector_aligned);
        stdx::where(decided, exit) = before;
        stdx::where(decided, count) = 0.0;
        exit.copy_to(&next.code[i], stdx::vector_aligned);
        count.copy_to(&next.n[i], stdx::vector_aligned);
    }
    for (std::size_t i = 0; i < n; ++i) index[i] = first + i;
    live.size = 0;
    settle(next, n, index.data(), live, out);
}

// One more excursion for every live point.
void sweep(Live& live, Stepped& next, const ModelMatrices& m, double max_bounces, const Results& out)
{
    for (std::size_t i = 0; i < live.size; i += width) {
        const CanonicalState<Batch> c{Batch(&live.xi[i], stdx::vector_aligned), Batch(&live.U[i], stdx::vector_aligned),
                                      Batch(&live.W[i], stdx::vector_aligned)};
        step(c, Batch(&live.n[i], stdx::vector_aligned) + 1.0, m, max_bounces, next, i);
    }
    const std::size_t n = live.size;
    live.size = 0;
    // settle() writes live.point[k] for k <= i only after reading point[i]: in place is safe.
    settle(next, n, live.point.data(), live, out);
}

}  // namespace

void count_each_simd(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    if (max_bounces == 0) {
        // Every launch is decided before its first excursion: nothing to vectorise.
        count_each(starts, m, max_bounces, wall_bounces, outcomes);
        return;
    }
    const Results out{wall_bounces, outcomes};
    Live live;
    Stepped next;
    std::array<std::size_t, block + width> index;
    // The padding lanes go through the arithmetic unused: give them harmless values.
    live.xi.fill(0.5);
    live.U.fill(-1.0);
    live.W.fill(0.0);
    live.n.fill(0.0);
    for (std::size_t first = 0; first < starts.size(); first += block) {
        const std::size_t n = std::min(block, starts.size() - first);
        first_sweep(starts.subview(first, n), m, max_bounces, next, live, index, out, first);
        while (live.size > 0) sweep(live, next, m, max_bounces, out);
    }
}

std::size_t simd_lanes() { return width; }

}  // namespace superball
