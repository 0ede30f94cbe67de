// The counting kernels of this build and the choice among them.
//
// A portable x86-64 build carries the vectorised kernel three times, compiled for the
// x86-64 baseline (SSE2), for AVX2+FMA (the x86-64-v3 level) and for AVX-512 (x86-64-v4),
// and runs the widest the processor supports: one binary, built on a login node, runs at
// full speed on compute nodes of another processor generation. A `-march=native` build
// (SUPERBALL_NATIVE) and builds for other processors carry one variant, compiled for the
// build's own instruction set. Every variant gives results identical bit for bit to the
// scalar count() (tests/core/test_kernels.cpp).
//
// Selection: `--kernel NAME` of `superball explore`, else the environment variable
// SUPERBALL_KERNEL, else the best variant this processor runs. Names: "simd" (the best
// variant), "scalar", or a variant's name ("baseline", "avx2", "avx512", "native").
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "count.hpp"

namespace superball {

// count_each()'s contract: results of starts[i] into wall_bounces[i], outcomes[i].
using CountKernel = void (*)(const StartsView&, const ModelMatrices&, std::uint32_t, std::span<std::uint32_t>,
                             std::span<std::uint8_t>);

struct KernelVariant {
    std::string_view name;             // what --kernel and SUPERBALL_KERNEL accept
    std::string_view instruction_set;  // e.g. "AVX2+FMA"; "scalar" for count_each()
    std::string_view requirement;      // what the processor needs, for messages ("" if nothing)
    std::size_t lanes = 1;             // doubles counted side by side
    CountKernel count = nullptr;
    bool (*runs_here)() = nullptr;     // whether this processor has the instructions
};

inline constexpr const char* kernel_environment_variable = "SUPERBALL_KERNEL";

// The scalar kernel, count_each().
const KernelVariant& scalar_kernel();

// The vectorised variants compiled into this build, narrowest first (at least one).
std::span<const KernelVariant> simd_kernels();

// The widest vectorised variant this processor runs (the baseline runs everywhere).
const KernelVariant& best_kernel();

// The kernel called `name` ("simd", "scalar" or a variant). Throws InputError naming
// `source` (e.g. "--kernel avx512", "SUPERBALL_KERNEL=avx512") when the name is unknown or
// the processor cannot run that variant; the message lists what this processor runs.
const KernelVariant& kernel_named(std::string_view name, std::string_view source);
// The same among `variants` (narrowest first, as simd_kernels() lists them): lets the tests
// check the refusals on any processor.
const KernelVariant& kernel_named(std::string_view name, std::string_view source,
                                  std::span<const KernelVariant> variants);

// The kernel a run uses: `flag` (a --kernel value) when not empty, else the
// SUPERBALL_KERNEL environment variable when set and not empty, else best_kernel().
const KernelVariant& select_kernel(std::string_view flag);

// "avx2 (AVX2+FMA, 4 lanes)".
std::string describe(const KernelVariant& k);
// describe() of the variant (scalar_kernel() or one of simd_kernels()) whose count is `k`,
// for the provenance of a run that was handed the function; "a kernel of the caller's"
// for any other.
std::string describe(CountKernel k);

// The cores this process may run on (its CPU affinity; else the hardware's threads, at
// least 1): the default number of counting threads.
unsigned usable_cores();

// For --version: the kernel in use and the variants this build and processor have, e.g.
// "counting kernel: avx512 (AVX-512, 8 lanes); compiled in: baseline, avx2, avx512; this
// processor runs: baseline, avx2, avx512".
std::string kernel_report();

}  // namespace superball
