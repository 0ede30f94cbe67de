// Microbenchmarks of the result-file layer: the per-tile checksum written with every tile.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "io/result_file.hpp"

namespace {

// One tile of `range(0)` points; items/s is points per second.
void BM_tile_checksum(benchmark::State& state)
{
    const auto n = static_cast<std::size_t>(state.range(0));
    std::vector<std::uint32_t> counts(n);
    std::vector<std::uint8_t> outcomes(n);
    for (std::size_t i = 0; i < n; ++i) {
        counts[i] = static_cast<std::uint32_t>(i % 7);
        outcomes[i] = static_cast<std::uint8_t>(i % 4);
    }
    for (auto _ : state) benchmark::DoNotOptimize(superball::tile_checksum(1, counts, outcomes));
    state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_tile_checksum)->Arg(65536);

}  // namespace

BENCHMARK_MAIN();
