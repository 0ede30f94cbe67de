#include "count_simd.hpp"

#include <algorithm>
#include <array>
#include <experimental/simd>

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

struct Live {
    // Padded by one batch so the last, partial batch can be loaded and stored whole.
    alignas(64) std::array<double, block + width> xi, U, W, n;
    std::array<std::size_t, block + width> point;
    std::size_t size = 0;
};

// Stores (wall_bounces, outcome) of point i.
struct Results {
    std::span<std::uint32_t> wall_bounces;
    std::span<std::uint8_t> outcomes;

    void store(std::size_t i, std::uint32_t n, Outcome o) const
    {
        wall_bounces[i] = n;
        outcomes[i] = static_cast<std::uint8_t>(o);
    }
};

// One sweep: G applied once to every live point, batch by batch, then the exits of
// SPEC.md section 3 in the order count() checks them. Points that stay are packed to
// the front again at once (in place: a point never moves up), which is the lane refill:
// the next sweep's batches are full of live points, however long some of them live.
// Every point's current count is stored at every step, so finishing needs no branch;
// a point that goes on is simply stored again later.
void sweep(Live& live, const ModelMatrices& m, double max_bounces, const Results& out)
{
    std::size_t kept = 0;
    alignas(64) std::array<double, width> xi, U, W, n, outcome;
    for (std::size_t i = 0; i < live.size; i += width) {
        const CanonicalState<Batch> c{Batch(&live.xi[i], stdx::element_aligned), Batch(&live.U[i], stdx::element_aligned),
                                      Batch(&live.W[i], stdx::element_aligned)};
        const CanonicalStep<Batch> s = canonical_map(c, m);
        const Batch count = Batch(&live.n[i], stdx::element_aligned) + 1.0;
        const auto left = s.next.U >= 0.0;
        const auto missed = !(s.next.xi < 1.0);
        const auto capped = count >= max_bounces;
        // 0: goes on; otherwise the Outcome code, left taking precedence over missed over capped.
        Batch code = 0.0;
        stdx::where(capped, code) = static_cast<double>(Outcome::capped);
        stdx::where(missed, code) = static_cast<double>(Outcome::missed);
        stdx::where(left, code) = static_cast<double>(Outcome::left);
        s.next.xi.copy_to(xi.data(), stdx::vector_aligned);
        s.next.U.copy_to(U.data(), stdx::vector_aligned);
        s.next.W.copy_to(W.data(), stdx::vector_aligned);
        count.copy_to(n.data(), stdx::vector_aligned);
        code.copy_to(outcome.data(), stdx::vector_aligned);
        const std::size_t lanes = std::min(width, live.size - i);
        for (std::size_t l = 0; l < lanes; ++l) {
            const std::size_t p = live.point[i + l];
            out.store(p, static_cast<std::uint32_t>(n[l]), static_cast<Outcome>(static_cast<int>(outcome[l])));
            live.xi[kept] = xi[l];
            live.U[kept] = U[l];
            live.W[kept] = W[l];
            live.n[kept] = n[l];
            live.point[kept] = p;
            kept += outcome[l] == 0.0;
        }
    }
    live.size = kept;
}

}  // namespace

void count_each_simd(std::span<const CanonicalState<double>> starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    const Results out{wall_bounces, outcomes};
    Live live;
    // Harmless values in the padding, which goes through the arithmetic unused.
    live.xi.fill(0.5);
    live.U.fill(-1.0);
    live.W.fill(0.0);
    live.n.fill(0.0);
    for (std::size_t first = 0; first < starts.size(); first += block) {
        const std::size_t last = std::min(starts.size(), first + block);
        live.size = 0;
        for (std::size_t i = first; i < last; ++i) {
            const CanonicalState<double>& s = starts[i];
            // Points decided before any excursion, as count() decides them.
            if (!is_launch(s)) {
                out.store(i, 0, Outcome::invalid);
            } else if (!(s.xi < 1.0)) {
                out.store(i, 0, Outcome::missed);
            } else if (max_bounces == 0) {
                out.store(i, 0, Outcome::capped);
            } else {
                const std::size_t k = live.size++;
                live.xi[k] = s.xi;
                live.U[k] = s.U;
                live.W[k] = s.W;
                live.n[k] = 0.0;
                live.point[k] = i;
            }
        }
        while (live.size > 0) sweep(live, m, max_bounces, out);
    }
}

std::size_t simd_lanes() { return width; }

}  // namespace superball
