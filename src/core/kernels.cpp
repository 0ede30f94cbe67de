#include "kernels.hpp"

#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <thread>

#include "count_simd.hpp"
#include "count_simd_variant.hpp"
#include "input.hpp"

// The variants src/CMakeLists.txt compiled into this build (SUPERBALL_SIMD_<NAME>).
#ifdef SUPERBALL_SIMD_BASELINE
SUPERBALL_DECLARE_SIMD_VARIANT(simd_baseline)
#endif
#ifdef SUPERBALL_SIMD_AVX2
SUPERBALL_DECLARE_SIMD_VARIANT(simd_avx2)
#endif
#ifdef SUPERBALL_SIMD_AVX512
SUPERBALL_DECLARE_SIMD_VARIANT(simd_avx512)
#endif
#ifdef SUPERBALL_SIMD_NATIVE
SUPERBALL_DECLARE_SIMD_VARIANT(simd_native)
#endif

namespace superball {

namespace {

using RawKernel = void (*)(const simd_variant::Arrays&, const ModelMatrices&, std::uint32_t);

// A variant behind count_each()'s interface. This file is compiled for the baseline, so
// the span accessors run everywhere; only the call goes to the wider instructions.
template <RawKernel raw>
void count_with(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    if (max_bounces == 0) {
        // Every launch is decided before its first excursion: nothing to vectorise.
        count_each(starts, m, max_bounces, wall_bounces, outcomes);
        return;
    }
    raw({starts.xi.data(), starts.U.data(), starts.W.data(), starts.size(), wall_bounces.data(), outcomes.data()}, m,
        max_bounces);
}

bool everywhere() { return true; }

#if defined(SUPERBALL_SIMD_AVX2) || defined(SUPERBALL_SIMD_AVX512)
// Exactly the extensions src/CMakeLists.txt compiles the variants with. libgcc (and
// compiler-rt) report AVX and AVX-512 only when the operating system saves their
// registers, so "supported" here means usable.
bool has_avx2()
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
           __builtin_cpu_supports("bmi2");
}

#endif

#ifdef SUPERBALL_SIMD_AVX512
bool has_avx512()
{
    return has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512bw");
}
#endif

// Names a variant of another kind of build may have: a request for one of them is not a
// typing error, and the message says which build has it.
constexpr std::string_view other_builds_hint =
    "; a portable x86-64 build (cmake --preset release) has baseline, avx2 and avx512, a -march=native build "
    "(cmake --preset native) has native";

bool is_variant_name(std::string_view name)
{
    return name == "baseline" || name == "avx2" || name == "avx512" || name == "native";
}

// The widest of `variants` this processor runs; the first needs nothing beyond the build's
// own flags.
const KernelVariant& best_of(std::span<const KernelVariant> variants)
{
    for (auto k = variants.rbegin(); k != variants.rend(); ++k) {
        if (k->runs_here()) return *k;
    }
    return variants.front();
}

std::string join_names(std::span<const KernelVariant> variants, bool runnable)
{
    std::string s;
    for (const KernelVariant& k : variants) {
        if (runnable && !k.runs_here()) continue;
        s += (s.empty() ? "" : ", ") + std::string(k.name);
    }
    return s;
}

std::string join_accepted(std::span<const KernelVariant> variants)
{
    return "simd (here " + std::string(best_of(variants).name) + "), scalar, " + join_names(variants, true);
}

}  // namespace

const KernelVariant& scalar_kernel()
{
    static constexpr KernelVariant scalar{"scalar", "scalar", "", 1, &count_each, &everywhere};
    return scalar;
}

std::span<const KernelVariant> simd_kernels()
{
    // Built once: the names of the instruction sets come from the variants themselves,
    // that is from the compiler's view of the flags each was compiled with.
    static const KernelVariant variants[] = {
#ifdef SUPERBALL_SIMD_BASELINE
        {"baseline", simd_baseline::instruction_set(), "", simd_baseline::lanes(),
         &count_with<&simd_baseline::count_each>, &everywhere},
#endif
#ifdef SUPERBALL_SIMD_AVX2
        {"avx2", simd_avx2::instruction_set(), "AVX2, FMA, BMI1 and BMI2 (x86-64-v3)", simd_avx2::lanes(),
         &count_with<&simd_avx2::count_each>, &has_avx2},
#endif
#ifdef SUPERBALL_SIMD_AVX512
        {"avx512", simd_avx512::instruction_set(), "AVX-512 F, CD, VL, DQ and BW (x86-64-v4)", simd_avx512::lanes(),
         &count_with<&simd_avx512::count_each>, &has_avx512},
#endif
#ifdef SUPERBALL_SIMD_NATIVE
        // The whole binary needs the build machine's instructions: if it runs, so does this.
        {"native", simd_native::instruction_set(), "", simd_native::lanes(), &count_with<&simd_native::count_each>,
         &everywhere},
#endif
    };
    return variants;
}

const KernelVariant& best_kernel()
{
    static const KernelVariant& best = best_of(simd_kernels());
    return best;
}

const KernelVariant& kernel_named(std::string_view name, std::string_view source)
{
    return kernel_named(name, source, simd_kernels());
}

const KernelVariant& kernel_named(std::string_view name, std::string_view source,
                                  std::span<const KernelVariant> variants)
{
    if (name == "simd") return best_of(variants);
    if (name == "scalar") return scalar_kernel();
    for (const KernelVariant& k : variants) {
        if (k.name != name) continue;
        if (k.runs_here()) return k;
        throw InputError(std::string(source) + ": this processor cannot run the " + std::string(name) +
                         " kernel (it needs " + std::string(k.requirement) + "); accepted here: " +
                         join_accepted(variants));
    }
    std::string message = std::string(source) + ": ";
    if (is_variant_name(name)) {
        message += "this build has no " + std::string(name) + " kernel (it has " + join_names(variants, false) + ")" +
                   std::string(other_builds_hint);
    } else {
        message += "unknown kernel '" + std::string(name) + "'";
    }
    throw InputError(message + "; accepted here: " + join_accepted(variants));
}

const KernelVariant& select_kernel(std::string_view flag)
{
    if (!flag.empty()) return kernel_named(flag, "--kernel " + std::string(flag));
    const char* env = std::getenv(kernel_environment_variable);
    if (env != nullptr && *env != '\0') {
        return kernel_named(env, std::string(kernel_environment_variable) + "=" + env);
    }
    return best_kernel();
}

std::string describe(const KernelVariant& k)
{
    if (k.lanes == 1) return std::string(k.name);
    return std::string(k.name) + " (" + std::string(k.instruction_set) + ", " + std::to_string(k.lanes) + " lanes)";
}

unsigned usable_cores()
{
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return static_cast<unsigned>(CPU_COUNT(&set));
    return std::max(1u, std::thread::hardware_concurrency());
}

std::string describe(CountKernel k)
{
    if (k == scalar_kernel().count) return describe(scalar_kernel());
    for (const KernelVariant& v : simd_kernels()) {
        if (v.count == k) return describe(v);
    }
    return "a kernel of the caller's";
}

std::string kernel_report()
{
    std::string in_use;
    try {
        in_use = describe(select_kernel({}));
    } catch (const InputError& e) {
        in_use = std::string("none (") + e.what() + ")";
    }
    return "counting kernel: " + in_use + "; compiled in: " + join_names(simd_kernels(), false) +
           "; this processor runs: " + join_names(simd_kernels(), true);
}

void count_each_simd(const StartsView& starts, const ModelMatrices& m, std::uint32_t max_bounces,
                     std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes)
{
    best_kernel().count(starts, m, max_bounces, wall_bounces, outcomes);
}

}  // namespace superball
