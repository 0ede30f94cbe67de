// The interface between the kernel registry (kernels.cpp) and the variants of the
// vectorised kernel, each compiled from count_simd.cpp for one instruction set
// (src/CMakeLists.txt). Plain pointers only: a variant's object file must not define any
// symbol that code compiled for another instruction set also defines (an inline function
// or template instantiation the linker could pick from the wrong variant), and std::span
// or StartsView members would be such symbols in a build without inlining.
// tests/core/check_kernel_isolation.cmake checks the object files.
#pragma once

#include <cstddef>
#include <cstdint>

#include "impact.hpp"

namespace superball::simd_variant {

// Start i is (xi[i], U[i], W[i]); its results go to wall_bounces[i] and outcomes[i].
struct Arrays {
    const double* xi;
    const double* U;
    const double* W;
    std::size_t size;
    std::uint32_t* wall_bounces;
    std::uint8_t* outcomes;
};

}  // namespace superball::simd_variant

// The entry points of one variant, in namespace superball::NS:
//   count_each        count_each()'s contract, for max_bounces >= 1
//   instruction_set   the vector instructions it was compiled for, e.g. "AVX2+FMA"
//   lanes             doubles per vector register
#define SUPERBALL_DECLARE_SIMD_VARIANT(NS)                                                                       \
    namespace superball::NS {                                                                                    \
    void count_each(const simd_variant::Arrays& points, const ModelMatrices& m, std::uint32_t max_bounces);      \
    const char* instruction_set();                                                                               \
    std::size_t lanes();                                                                                         \
    }
