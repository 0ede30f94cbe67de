// Microbenchmarks of the map step and the counting kernels (Google Benchmark).
//
//   build/native/tests/bench/bench_kernel            (the native preset: -march=native)
//
// Reported: ns per map iteration (items = iterations of G) and points/s of the kernels
// on the issue-4 slice U = -1, xi in (0, 1), W in [-3, 3], e = alpha = 0.9.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "core/count.hpp"
#include "core/count_simd.hpp"

namespace {

using namespace superball;


const ModelMatrices slice_model = ModelMatrices::of(Model::uniform(0.9, 0.9));

// n x n cell centres of the benchmark slice.
std::vector<CanonicalState<double>> slice(std::size_t n)
{
    std::vector<CanonicalState<double>> s;
    s.reserve(n * n);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = 0; k < n; ++k) {
            s.push_back({(static_cast<double>(i) + 0.5) / static_cast<double>(n), -1.0,
                         -3.0 + (static_cast<double>(k) + 0.5) * 6.0 / static_cast<double>(n)});
        }
    }
    return s;
}

// Latency of one step of G: each step waits for the one before (its result feeds the
// next start, through a multiplication by zero the compiler cannot remove).
void BM_canonical_map(benchmark::State& state)
{
    CanonicalState<double> c{0.05, -1.0, -2.0};
    double zero = 0.0;
    benchmark::DoNotOptimize(zero);
    for (auto _ : state) {
        const CanonicalStep<double> s = canonical_map(c, slice_model);
        c = {0.05 + zero * s.next.xi, -1.0, -2.0};
    }
    benchmark::DoNotOptimize(c);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_canonical_map);

void BM_physical_map(benchmark::State& state)
{
    const PhysicalState<double> s{0.02, -2.0, 2.0, -5.0};
    for (auto _ : state) {
        PhysicalState<double> in = s;
        benchmark::DoNotOptimize(in);
        benchmark::DoNotOptimize(physical_map(in, slice_model, 9.81));
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_physical_map);

// Counts every start once per iteration with the scalar or the vectorised kernel;
// items are points, and the counter the time per iteration of G.
template <bool simd>
void run_kernel(benchmark::State& state, const std::vector<CanonicalState<double>>& starts)
{
    std::vector<std::uint32_t> wb(starts.size());
    std::vector<std::uint8_t> oc(starts.size());
    const Starts points = Starts::of(starts);
    for (auto _ : state) {
        if constexpr (simd) {
            count_each_simd(points.view(), slice_model, 1000, wb, oc);
        } else {
            count_each(points.view(), slice_model, 1000, wb, oc);
        }
        benchmark::ClobberMemory();
    }
    std::uint64_t iterations = 0;
    for (const auto w : wb) iterations += w;
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * starts.size()));
    state.counters["time_per_map_iteration"] = benchmark::Counter(
        static_cast<double>(state.iterations() * iterations), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

template <bool simd>
void BM_count_slice(benchmark::State& state)
{
    run_kernel<simd>(state, slice(static_cast<std::size_t>(state.range(0))));
}
// 4096: the full benchmark slice of tests/bench/run.sh (16.7 M points).
BENCHMARK_TEMPLATE(BM_count_slice, false)->Arg(512)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_count_slice, true)->Arg(512)->Arg(4096)->Unit(benchmark::kMillisecond);

// Long-lived points only (the region xi < 0.05, W < -2 of the slice, where counts are
// highest): measures the arithmetic throughput of the kernels rather than lane refill.
template <bool simd>
void BM_count_long_lived(benchmark::State& state)
{
    std::vector<CanonicalState<double>> starts;
    for (int i = 0; i < 64; ++i) {
        for (int k = 0; k < 64; ++k) starts.push_back({0.0005 + 0.0007 * i, -1.0, -2.99 + 0.015 * k});
    }
    run_kernel<simd>(state, starts);
}
BENCHMARK_TEMPLATE(BM_count_long_lived, false)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_count_long_lived, true)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
