// One variant of the vectorised counting kernel: several start points advanced together
// through G.
//
// SIMD through std::experimental::simd (libstdc++'s Parallelism TS 2, shipped with the
// compiler: no extra dependency): its native type maps to SSE2, AVX2 or AVX-512 registers
// according to the instruction set this file is compiled for, and the map is the same
// template canonical_map<T> as the scalar count(), instantiated on a SIMD batch. With
// -ffp-contract=off (set for the whole project) every lane performs exactly the scalar
// operations in the same order, and IEEE division and square root are correctly rounded
// in both, so every variant agrees with the scalar kernel bit for bit; tests/core checks
// it on the reference points and grids.
//
// This file is compiled once per variant (src/CMakeLists.txt: the baseline, AVX2+FMA and
// AVX-512 in a portable x86-64 build; one variant elsewhere), each time with
// SUPERBALL_SIMD_NAMESPACE naming the namespace of its entry points. kernels.cpp picks the
// variant the processor runs. Nothing here may be an inline function or template that
// other code also instantiates (std::span, std::array, std::min...): the linker keeps one
// copy of such a symbol for the whole program, and the AVX-512 copy would run on a
// processor without AVX-512. Only the map templates on this variant's own SIMD type, whose
// names no other variant shares, are left (check_kernel_isolation.cmake).
// First, so that the pragmas cover the compiler's intrinsics headers it brings in: GCC 12's
// avx512fintrin.h makes an "undefined" register with `__m512d __Y = __Y;`
// (_mm512_undefined_pd, used by _mm512_sqrt_pd), and once inlined into the AVX-512
// variant that self-initialisation is reported as a use of an uninitialised value (GCC 13
// no longer does). Only these headers are exempt; this file's own code is still checked.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#ifndef __clang__  // GCC's name: clang would warn about an unknown option
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <experimental/simd>
#pragma GCC diagnostic pop

#include <limits>

#include "count.hpp"
#include "count_simd_variant.hpp"

#ifndef SUPERBALL_SIMD_NAMESPACE
#error "compile with -DSUPERBALL_SIMD_NAMESPACE=simd_<variant> (src/CMakeLists.txt)"
#endif

SUPERBALL_DECLARE_SIMD_VARIANT(SUPERBALL_SIMD_NAMESPACE)

namespace superball::SUPERBALL_SIMD_NAMESPACE {

namespace {

namespace stdx = std::experimental;
// One register of the widest vector unit this file is compiled for: 2 lanes with SSE2
// (the x86-64 baseline), 4 with AVX2, 8 with AVX-512. (fixed_size_simd<double, 8> was
// measured 3.7x slower per lane with GCC 12: its generic implementation does not keep the
// lanes in registers.)
using Batch = stdx::native_simd<double>;
constexpr std::size_t width = Batch::size();

// Points are taken a block at a time; the block's live points are kept packed at the
// front of structure-of-arrays buffers, padded by one batch so the last, partial batch can
// be loaded and stored whole.
constexpr std::size_t block = 512;
constexpr std::size_t padded = block + width;

// Exit codes as doubles, so that they are computed with vector selects: an Outcome, or
// go_on for a point that needs another excursion.
constexpr double go_on = -1.0;
constexpr double code(Outcome o) { return static_cast<double>(o); }

struct Live {
    alignas(64) double xi[padded];
    alignas(64) double U[padded];
    alignas(64) double W[padded];
    alignas(64) double n[padded];
    std::size_t point[padded];
    std::size_t size;
};

// What one application of G made of a batch of points: the new state, the new count and
// the exit code.
struct Stepped {
    alignas(64) double xi[padded];
    alignas(64) double U[padded];
    alignas(64) double W[padded];
    alignas(64) double n[padded];
    alignas(64) double code[padded];
};

// G applied to a batch: the exits of SPEC.md section 3 after the step, in the order
// count() checks them (invalid takes precedence over left over missed over capped).
template <ImpactLaw law>
[[gnu::always_inline]] inline void step(const CanonicalState<Batch>& c, const Batch& count, const ModelMatrices& m,
                                        double max_bounces, Stepped& next, std::size_t i)
{
    const CanonicalStep<Batch> s = canonical_map<law>(c, m);
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
void settle(const Stepped& next, std::size_t n, const std::size_t* point, Live& live, const simd_variant::Arrays& out)
{
    // Locals, not members: a store through the uint8_t outcomes may alias anything, and
    // would make the compiler reload every pointer and the size after it.
    std::uint32_t* const wall_bounces = out.wall_bounces;
    std::uint8_t* const outcomes = out.outcomes;
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

// The first excursion of the n points from `first` on, read straight from the input: the
// checks count() makes before any excursion (not a launch, missing at once) are vector
// compares too. Two passes, the arithmetic alone over all batches and then the
// bookkeeping point by point: kept apart, each loop is short enough for the processor to
// overlap many batches; interleaved, every batch waited on its own divisions and square
// root.
// The two sweeps are flattened (every call in them inlined): with both impact laws
// instantiated, GCC 12 left canonical_map, the impacts, the lane select detail::choose
// (16 calls in the AVX2 object) and `representable` out of line in them, each call passing
// the batches through memory (the default model lost 6-9 % of its speed on AVX2,
// docs/speed.md).
template <ImpactLaw law>
[[gnu::flatten]] void first_sweep(const simd_variant::Arrays& in, std::size_t first, std::size_t n, const ModelMatrices& m,
                 double max_bounces, Stepped& next, Live& live, std::size_t* index)
{
    const double* const xi = in.xi + first;
    const double* const U = in.U + first;
    const double* const W = in.W + first;
    for (std::size_t i = 0; i < n; i += width) {
        CanonicalState<Batch> c;
        if (i + width <= n) {
            c = {Batch(xi + i, stdx::element_aligned), Batch(U + i, stdx::element_aligned),
                 Batch(W + i, stdx::element_aligned)};
        } else {
            // The last batch is partial: its missing lanes get a harmless launch.
            alignas(64) double part[3][width];
            for (std::size_t l = 0; l < width; ++l) {
                const bool inside = i + l < n;
                part[0][l] = inside ? xi[i + l] : 0.5;
                part[1][l] = inside ? U[i + l] : -1.0;
                part[2][l] = inside ? W[i + l] : 0.0;
            }
            c = {Batch(part[0], stdx::vector_aligned), Batch(part[1], stdx::vector_aligned),
                 Batch(part[2], stdx::vector_aligned)};
        }
        step<law>(c, Batch(1.0), m, max_bounces, next, i);
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
    settle(next, n, index, live, in);
}

// One more excursion for every live point.
template <ImpactLaw law>
[[gnu::flatten]] void sweep(Live& live, Stepped& next, const ModelMatrices& m, double max_bounces, const simd_variant::Arrays& out)
{
    for (std::size_t i = 0; i < live.size; i += width) {
        const CanonicalState<Batch> c{Batch(&live.xi[i], stdx::vector_aligned), Batch(&live.U[i], stdx::vector_aligned),
                                      Batch(&live.W[i], stdx::vector_aligned)};
        step<law>(c, Batch(&live.n[i], stdx::vector_aligned) + 1.0, m, max_bounces, next, i);
    }
    const std::size_t n = live.size;
    live.size = 0;
    // settle() writes live.point[k] for k <= i only after reading point[i]: in place is safe.
    settle(next, n, live.point, live, out);
}

template <ImpactLaw law>
void count_blocks(const simd_variant::Arrays& points, const ModelMatrices& m, std::uint32_t max_bounces)
{
    Live live;
    Stepped next;
    std::size_t index[padded];
    // The padding lanes go through the arithmetic unused: give them harmless values.
    for (std::size_t i = 0; i < padded; ++i) {
        live.xi[i] = 0.5;
        live.U[i] = -1.0;
        live.W[i] = 0.0;
        live.n[i] = 0.0;
    }
    const auto cap = static_cast<double>(max_bounces);
    for (std::size_t first = 0; first < points.size; first += block) {
        const std::size_t n = points.size - first < block ? points.size - first : block;
        first_sweep<law>(points, first, n, m, cap, next, live, index);
        while (live.size > 0) sweep<law>(live, next, m, cap, points);
    }
}

}  // namespace

// Without friction every impact grips: the Cross model's arithmetic alone, the same bits as
// Walton's law with infinite mu without computing the friction limit (the kernel's speed).
void count_each(const simd_variant::Arrays& points, const ModelMatrices& m, std::uint32_t max_bounces)
{
    if (m.frictional) count_blocks<ImpactLaw::walton>(points, m, max_bounces);
    else count_blocks<ImpactLaw::cross>(points, m, max_bounces);
}

const char* instruction_set()
{
#if defined(__AVX512F__)
    return "AVX-512";
#elif defined(__AVX2__) && defined(__FMA__)
    return "AVX2+FMA";
#elif defined(__AVX2__)
    return "AVX2";
#elif defined(__AVX__)
    return "AVX";
#elif defined(__SSE2__)
    return "SSE2";
#elif defined(__ARM_FEATURE_SVE)
    return "SVE";
#elif defined(__ARM_NEON)
    return "NEON";
#elif defined(__VSX__)
    return "VSX";
#elif defined(__ALTIVEC__)
    return "AltiVec";
#else
    return "no vector unit known to std::experimental::simd";
#endif
}

std::size_t lanes() { return width; }

}  // namespace superball::SUPERBALL_SIMD_NAMESPACE
