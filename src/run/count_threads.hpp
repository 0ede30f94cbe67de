// Counting many launches held in memory on the threads of this process, without MPI or
// files: the library function behind the Python module's count().
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "core/count.hpp"
#include "core/kernels.hpp"

namespace superball {

// The canonical starts of points [first, first + n): written into `buffer` (resized to n)
// and viewed there, or, when the caller holds them as arrays of doubles already, a view of
// those (no copy). Called on the counting threads, at once for different blocks.
using LoadStarts = std::function<StartsView(std::size_t first, std::size_t n, Starts& buffer)>;

struct ThreadedCount {
    CountKernel kernel = best_kernel().count;
    unsigned threads = 0;  // 0: usable_cores()
};

// Counts every point i < wall_bounces.size() (= outcomes.size()) from the start `load` gives,
// under model `m`, into wall_bounces[i] and outcomes[i], with `how.kernel` on `how.threads`
// threads. The points are taken in blocks, each thread taking the next block when it is
// done with one: the cost of a launch varies by orders of magnitude (one wall bounce to
// max_bounces), so equal shares would leave threads waiting. A block is large enough for
// the vector kernel to run full (it drains its lanes at the end of a call), small enough
// that the threads end together; fewer points than two blocks are counted on the calling
// thread alone. The results equal the kernel's on all points in one call, bit for bit. An
// exception from `load` stops the other threads at their next block and is rethrown.
void count_on_threads(const LoadStarts& load, const ModelMatrices& m, std::uint32_t max_bounces,
                      std::span<std::uint32_t> wall_bounces, std::span<std::uint8_t> outcomes, const ThreadedCount& how);

// The block size count_on_threads() uses for n points on `threads` threads.
std::size_t count_block(std::size_t n, unsigned threads);

}  // namespace superball
