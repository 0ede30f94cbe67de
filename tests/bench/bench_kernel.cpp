// Microbenchmarks of the map step and the counting kernels (Google Benchmark).
//
//   build/release/tests/bench/bench_kernel --benchmark_filter=count_slice
//
// Reported: ns per map iteration (items = iterations of G) and points/s of the scalar
// kernel and of every variant of the vectorised kernel this processor runs
// (core/kernels.hpp) on the issue-4 slice U = -1, xi in (0, 1), W in [-3, 3],
// e = alpha = 0.9 (BM_count_slice_mu1: the same with Coulomb friction mu = 1, SPEC.md 1b). The
// context line "superball" names the variants.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"

namespace {

using namespace superball;


const ModelMatrices slice_model = ModelMatrices::of(Model::uniform(0.9, 0.9));

// The same slice with Coulomb friction mu = 1 on both surfaces (SPEC.md 1b): the kernels'
// Walton path, where every impact takes its friction limit (BM_count_slice_mu1).
ModelMatrices frictional_slice_model()
{
    Model m = Model::uniform(0.9, 0.9);
    m.wall.mu = m.floor.mu = 1.0;
    return ModelMatrices::of(m);
}
const ModelMatrices slice_model_mu1 = frictional_slice_model();

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

// Counts every start once per iteration with `kernel`; items are points, and the counter
// the time per iteration of G.
void run_kernel(benchmark::State& state, const KernelVariant& kernel, const std::vector<CanonicalState<double>>& starts,
                const ModelMatrices& model = slice_model)
{
    std::vector<std::uint32_t> wb(starts.size());
    std::vector<std::uint8_t> oc(starts.size());
    const Starts points = Starts::of(starts);
    for (auto _ : state) {
        kernel.count(points.view(), model, 1000, wb, oc);
        benchmark::ClobberMemory();
    }
    std::uint64_t iterations = 0;
    for (const auto w : wb) iterations += w;
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * starts.size()));
    state.counters["time_per_map_iteration"] = benchmark::Counter(
        static_cast<double>(state.iterations() * iterations), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.SetLabel(describe(kernel));
}

// Long-lived points only (the region xi < 0.05, W < -2 of the slice, where counts are
// highest): measures the arithmetic throughput of the kernels rather than lane refill.
std::vector<CanonicalState<double>> long_lived()
{
    std::vector<CanonicalState<double>> starts;
    for (int i = 0; i < 64; ++i) {
        for (int k = 0; k < 64; ++k) starts.push_back({0.0005 + 0.0007 * i, -1.0, -2.99 + 0.015 * k});
    }
    return starts;
}

// The 8192^2 benchmark slice counted by the scalar kernel as a plain C++ loop would: a row
// of starts at a time, one core, nothing written. The yardstick of `explore -n 1` end to
// end (tests/bench/run_benchmarks.py); its total of wall bounces must equal the result's.
void BM_scalar_loop(benchmark::State& state)
{
    const std::size_t n = 8192;
    std::vector<CanonicalState<double>> row(n);
    std::vector<std::uint32_t> wb(n);
    std::vector<std::uint8_t> oc(n);
    std::uint64_t total = 0;
    for (auto _ : state) {
        total = 0;
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t k = 0; k < n; ++k) {
                row[k] = {(static_cast<double>(i) + 0.5) / static_cast<double>(n), -1.0,
                          -3.0 + (static_cast<double>(k) + 0.5) * 6.0 / static_cast<double>(n)};
            }
            scalar_kernel().count(Starts::of(row).view(), slice_model, 1000, wb, oc);
            for (const std::uint32_t w : wb) total += w;
        }
        benchmark::DoNotOptimize(total);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n * n));
    state.counters["total_wall_bounces"] = static_cast<double>(total);
}

// The launches of the file `path`: n doubles of xi, then n of U, then n of W (native byte
// order), as tests/bench/python_count.py writes them.
Starts read_launches(const char* path)
{
    std::FILE* f = std::fopen(path, "rb");
    if (!f) throw std::runtime_error(std::string("cannot read ") + path);
    std::vector<double> all;
    double buf[4096];
    std::size_t got = 0;
    while ((got = std::fread(buf, sizeof(double), 4096, f)) > 0) all.insert(all.end(), buf, buf + got);
    std::fclose(f);
    const std::size_t n = all.size() / 3;
    Starts s;
    s.xi.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n));
    s.U.assign(all.begin() + static_cast<std::ptrdiff_t>(n), all.begin() + static_cast<std::ptrdiff_t>(2 * n));
    s.W.assign(all.begin() + static_cast<std::ptrdiff_t>(2 * n), all.begin() + static_cast<std::ptrdiff_t>(3 * n));
    return s;
}

// The bare vectorised kernel on `launches`, split in equal contiguous parts among the
// benchmark's threads, each counting its part in one call (e = alpha = 0.9, max_bounces
// 1000): what the Python module's count() is measured against (tests/bench/python_count.py).
void BM_count_launches(benchmark::State& state, const Starts& launches)
{
    const auto threads = static_cast<std::size_t>(state.threads());
    const auto me = static_cast<std::size_t>(state.thread_index());
    const std::size_t first = launches.size() * me / threads, last = launches.size() * (me + 1) / threads;
    const StartsView part = launches.view().subview(first, last - first);
    std::vector<std::uint32_t> wb(part.size());
    std::vector<std::uint8_t> oc(part.size());
    for (auto _ : state) {
        best_kernel().count(part, slice_model, 1000, wb, oc);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * part.size()));
    state.SetLabel(describe(best_kernel()));
}

}  // namespace

// The kernels by name: BM_count_slice/<kernel>/<n> for the scalar kernel and every
// vectorised variant this processor runs (4096: the full benchmark slice of
// tests/bench/run.sh, 16.7 M points), BM_count_long_lived/<kernel>. Rates per second of
// wall time, as explore reports its own: on a shared machine the processor time of one
// thread overstates what a run gets.
int main(int argc, char** argv)
{
    std::vector<const KernelVariant*> kernels{&scalar_kernel()};
    for (const KernelVariant& k : simd_kernels()) {
        if (k.runs_here()) kernels.push_back(&k);
    }
    for (const KernelVariant* k : kernels) {
        for (const std::size_t n : {512, 4096}) {
            benchmark::RegisterBenchmark(("BM_count_slice/" + std::string(k->name) + "/" + std::to_string(n)).c_str(),
                                         [k, n](benchmark::State& state) { run_kernel(state, *k, slice(n)); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
        }
    }
    for (const KernelVariant* k : kernels) {
        for (const std::size_t n : {512, 4096}) {
            benchmark::RegisterBenchmark(("BM_count_slice_mu1/" + std::string(k->name) + "/" + std::to_string(n)).c_str(),
                                         [k, n](benchmark::State& state) { run_kernel(state, *k, slice(n), slice_model_mu1); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
        }
    }
    for (const KernelVariant* k : kernels) {
        benchmark::RegisterBenchmark(("BM_count_long_lived/" + std::string(k->name)).c_str(),
                                     [k](benchmark::State& state) { run_kernel(state, *k, long_lived()); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    benchmark::RegisterBenchmark("BM_scalar_loop/8192", BM_scalar_loop)->Unit(benchmark::kMillisecond)->UseRealTime();
    // BM_count_launches/threads:1 and :2, when SUPERBALL_BENCH_LAUNCHES names a file of launches.
    Starts launches;
    if (const char* path = std::getenv("SUPERBALL_BENCH_LAUNCHES"); path != nullptr && *path != '\0') {
        launches = read_launches(path);
        benchmark::RegisterBenchmark("BM_count_launches", [&launches](benchmark::State& state) {
            BM_count_launches(state, launches);
        })->Threads(1)->Threads(2)->Unit(benchmark::kMillisecond)->UseRealTime();
    }
    benchmark::AddCustomContext("superball", kernel_report());
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
