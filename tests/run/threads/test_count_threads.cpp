// count_on_threads and run_on_threads (run/count_threads.hpp, run/threads.hpp): counting on
// the threads of one process gives the kernel's results bit for bit, whatever the thread
// count, the block size or where the starts come from.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/count.hpp"
#include "core/kernels.hpp"
#include "run/count_threads.hpp"
#include "run/threads.hpp"

namespace superball {
namespace {

const ModelMatrices model = ModelMatrices::of(Model::uniform(0.9, 0.9));

// Launches across the region, some of them not admissible (U >= 0, xi <= 0, NaN).
Starts random_starts(std::size_t n, unsigned seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> xi(-0.05, 1.1), U(-3.0, 0.2), W(-4.0, 4.0);
    Starts s;
    for (std::size_t i = 0; i < n; ++i) s.push_back({xi(rng), U(rng), W(rng)});
    if (n > 10) s.set(7, {std::numeric_limits<double>::quiet_NaN(), -1.0, 0.0});
    return s;
}

struct Results {
    std::vector<std::uint32_t> counts;
    std::vector<std::uint8_t> outcomes;
};

Results direct(const Starts& s, std::uint32_t max_bounces)
{
    Results r{std::vector<std::uint32_t>(s.size()), std::vector<std::uint8_t>(s.size())};
    count_each(s.view(), model, max_bounces, r.counts, r.outcomes);
    return r;
}

Results threaded(const LoadStarts& load, std::size_t n, std::uint32_t max_bounces, unsigned threads)
{
    Results r{std::vector<std::uint32_t>(n, 7777), std::vector<std::uint8_t>(n, 99)};
    count_on_threads(load, model, max_bounces, r.counts, r.outcomes, {best_kernel().count, threads});
    return r;
}

TEST(CountOnThreads, EqualsTheScalarKernelAtAnyThreadCountAndSize)
{
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{4095}, std::size_t{70001}}) {
        const Starts s = random_starts(n, static_cast<unsigned>(n));
        const Results want = direct(s, 200);
        // The caller's arrays viewed in place, and copied into the thread's buffer.
        const LoadStarts view = [&](std::size_t first, std::size_t count, Starts&) { return s.view().subview(first, count); };
        const LoadStarts copy = [&](std::size_t first, std::size_t count, Starts& buffer) {
            buffer.resize(count);
            for (std::size_t i = 0; i < count; ++i) buffer.set(i, s.view()[first + i]);
            return buffer.view();
        };
        for (const unsigned threads : {1u, 2u, 3u, 7u}) {
            SCOPED_TRACE(testing::Message() << n << " points, " << threads << " threads");
            for (const LoadStarts* load : {&view, &copy}) {
                const Results got = threaded(*load, n, 200, threads);
                EXPECT_EQ(got.counts, want.counts);
                EXPECT_EQ(got.outcomes, want.outcomes);
            }
        }
    }
}

TEST(CountOnThreads, BlocksFillTheVectorKernelAndShareTheWork)
{
    EXPECT_EQ(count_block(10, 2), 4096u);                          // never smaller
    EXPECT_EQ(count_block(4'000'000, 2), 250'000u);                 // 8 blocks per thread
    EXPECT_EQ(count_block(std::size_t{1} << 30, 2), std::size_t{1} << 18);  // never larger
}

TEST(CountOnThreads, EveryBlockIsLoadedOnceAndFromSeveralThreads)
{
    const std::size_t n = 200'000;
    const Starts s = random_starts(n, 3);
    std::atomic<std::size_t> loaded{0};
    std::mutex m;
    std::condition_variable second_thread;
    std::set<std::thread::id> ids;
    // The first loads wait (up to 10 s) for a second thread to load a block: on a loaded
    // machine the calling thread could otherwise count every block before the others start
    // (this failed under ctest beside other jobs), which says nothing about the sharing.
    const LoadStarts load = [&](std::size_t first, std::size_t count, Starts&) {
        loaded += count;
        {
            std::unique_lock lock(m);
            ids.insert(std::this_thread::get_id());
            second_thread.notify_all();
            second_thread.wait_for(lock, std::chrono::seconds(10), [&] { return ids.size() >= 2; });
        }
        return s.view().subview(first, count);
    };
    const Results got = threaded(load, n, 1000, 4);
    EXPECT_EQ(loaded.load(), n);
    EXPECT_GE(ids.size(), 2u);
    const Results want = direct(s, 1000);
    EXPECT_EQ(got.counts, want.counts);
}

TEST(CountOnThreads, AFailingLoadStopsTheRunAndIsRethrown)
{
    const std::size_t n = 100'000;
    const Starts s = random_starts(n, 5);
    std::atomic<int> calls{0};
    const LoadStarts load = [&](std::size_t first, std::size_t count, Starts&) -> StartsView {
        if (++calls == 3) throw std::runtime_error("cannot read block");
        // A load takes a moment, as reading does: on a busy machine the other threads would
        // otherwise take every block before the failing one has stopped them.
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        return s.view().subview(first, count);
    };
    EXPECT_THROW(threaded(load, n, 1000, 3), std::runtime_error);
    // The other threads stopped at their next block instead of counting everything.
    EXPECT_LT(calls.load(), static_cast<int>((n + count_block(n, 3) - 1) / count_block(n, 3)));
}

TEST(RunOnThreads, RunsEveryBodyOnceAndTheFirstOnTheCallingThread)
{
    std::vector<std::atomic<int>> runs(5);
    std::thread::id first;
    run_on_threads(5, [&](unsigned i) {
        ++runs[i];
        if (i == 0) first = std::this_thread::get_id();
    });
    for (const auto& r : runs) EXPECT_EQ(r.load(), 1);
    EXPECT_EQ(first, std::this_thread::get_id());
    EXPECT_THROW(run_on_threads(3, [](unsigned i) {
                     if (i == 2) throw std::invalid_argument("body 2");
                 }),
                 std::invalid_argument);
}

}  // namespace
}  // namespace superball
