// The vectorised counting kernel: several start points advanced together through G, the
// same canonical_map template as the scalar count() on SIMD batches (count_simd.cpp).
// It is compiled for several instruction sets; core/kernels.hpp lists the variants and
// chooses among them.
#pragma once

#include <cstdint>
#include <span>

#include "count.hpp"

namespace superball {

// Same contract as count_each(), results identical to it, counted by the widest variant
// this processor runs (best_kernel()). Lane refill: when a point leaves, misses or is
// capped, its lane takes the next point of the input at once, so one long-lived point
// never holds the other lanes idle.
void count_each_simd(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes);

}  // namespace superball
