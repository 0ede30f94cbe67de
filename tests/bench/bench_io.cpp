// Microbenchmarks of the result-file layer: the per-tile checksum written with every tile.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "io/partial_file.hpp"

namespace {

// One tile of `range(0)` points as a 16-bit file stores it; items/s is points per second.
void BM_tile_checksum(benchmark::State& state)
{
    const auto n = static_cast<std::size_t>(state.range(0));
    std::vector<std::byte> counts(2 * n), outcomes(n);
    for (std::size_t i = 0; i < n; ++i) {
        counts[2 * i] = static_cast<std::byte>(i % 7);
        outcomes[i] = static_cast<std::byte>(i % 4);
    }
    for (auto _ : state) benchmark::DoNotOptimize(superball::tile_checksum(1, counts, outcomes));
    state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_tile_checksum)->Arg(65536);

}  // namespace

BENCHMARK_MAIN();
