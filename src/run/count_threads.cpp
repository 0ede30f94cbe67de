#include "count_threads.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "run/threads.hpp"

namespace superball {

std::size_t count_block(std::size_t n, unsigned threads)
{
    // About 8 blocks per thread, so that the slowest block costs the others little at the
    // end; at least 4096 points (a few microseconds of scheduling on 30-100 us of counting),
    // at most 2^18 (the vector kernel's drain at the end of a block is then negligible).
    const std::size_t per = n / (std::size_t{8} * std::max(1u, threads));
    return std::clamp<std::size_t>(per, 4096, std::size_t{1} << 18);
}

void count_on_threads(const LoadStarts& load, const ModelMatrices& m, std::uint32_t max_bounces,
                      std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes, const ThreadedCount& how)
{
    const std::size_t n = wall_bounces.size();
    if (outcomes.size() != n) throw std::invalid_argument("count_on_threads: wall_bounces and outcomes differ in size");
    const unsigned wanted = how.threads != 0 ? how.threads : usable_cores();
    const std::size_t block = count_block(n, wanted);
    const std::size_t blocks = (n + block - 1) / block;
    const auto threads = static_cast<unsigned>(std::min<std::size_t>(wanted, blocks < 2 ? 1 : blocks));
    std::atomic<std::size_t> next{0};
    std::atomic<bool> failed{false};
    run_on_threads(threads, [&](unsigned) {
        Starts buffer;
        for (;;) {
            const std::size_t b = next.fetch_add(1, std::memory_order_relaxed);
            if (b >= blocks || failed.load(std::memory_order_relaxed)) return;
            const std::size_t first = b * block, count = std::min(block, n - first);
            try {
                const StartsView starts = load(first, count, buffer);
                if (starts.size() != count) throw std::logic_error("count_on_threads: a block of the wrong size was loaded");
                how.kernel(starts, m, max_bounces, wall_bounces.subspan(first, count), outcomes.subspan(first, count));
            } catch (...) {
                failed = true;
                throw;
            }
        }
    });
}

}  // namespace superball
