// The vectorised counting kernel: several start points advanced together through G.
//
// SIMD through std::experimental::simd (libstdc++'s Parallelism TS 2, shipped with the
// compiler: no extra dependency): its types map to SSE2, AVX2 or AVX-512 registers
// according to the build's -march, and the map is the same template canonical_map<T>
// as the scalar count(), instantiated on a SIMD batch. With -ffp-contract=off (set for
// the whole project) every lane performs exactly the scalar operations in the same
// order, and IEEE division and square root are correctly rounded in both, so the two
// kernels agree bit for bit; tests/core checks it on the reference points and grids.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "count.hpp"

namespace superball {

// Same contract as count_each(), results identical to it. Lane refill: when a point
// leaves, misses or is capped, its lane takes the next point of the input at once, so
// one long-lived point never holds the other lanes idle.
void count_each_simd(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes);

// Number of lanes of the kernel in this build.
std::size_t simd_lanes();

}  // namespace superball
