// The worker pool that counts for every request. A request's work is cut into blocks;
// the workers take blocks from the pending requests in turn (round robin), so a large or
// slow request shares the cores with the others instead of holding them, and one small
// request is counted by every idle worker at once. Blocks are short (region.hpp), so a
// request whose client went away, or that ran past its time limit, stops within a block.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace superball::serve {

using Clock = std::chrono::steady_clock;

class Task {
public:
    enum class Status { running, done, cancelled, timed_out, failed };

    // `blocks` calls of run(b), b = 0 .. blocks - 1, none started after `deadline`.
    Task(std::size_t blocks, std::function<void(std::size_t)> run, Clock::time_point deadline);

    // The client went away: no further block starts.
    void cancel() { cancelled_ = true; }

    // Waits until every block has run or been skipped, at most `timeout`; the status then
    // (running if the wait timed out).
    Status wait_for(std::chrono::milliseconds timeout);
    // The exception a block threw (status failed).
    std::exception_ptr error() const;

private:
    friend class Pool;
    // Runs block b unless the task is cancelled, failed or past its deadline: whether it
    // ran, whether it was the task's last, and how the task stands then.
    struct BlockResult {
        bool run, last, cancelled, timed_out;
    };
    BlockResult run_block(std::size_t b);

    const std::size_t blocks_;
    const std::function<void(std::size_t)> run_;
    const Clock::time_point deadline_;
    std::size_t next_ = 0;  // guarded by the pool's mutex
    std::atomic<bool> cancelled_{false};

    mutable std::mutex mutex_;
    std::condition_variable finished_cv_;
    std::size_t finished_ = 0;
    bool timed_out_ = false;
    std::exception_ptr error_;
};

// Counters since start, for /api/info and the tests.
struct PoolStats {
    std::uint64_t tasks = 0;
    std::uint64_t blocks_run = 0;
    std::uint64_t blocks_skipped = 0;  // of cancelled, timed-out or failed tasks
    std::uint64_t cancelled = 0;
    std::uint64_t timed_out = 0;
    std::uint64_t refused = 0;         // queue full
    std::size_t pending = 0;           // tasks with blocks not yet started
};

class Pool {
public:
    Pool(unsigned threads, std::size_t max_pending);
    ~Pool();
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;

    unsigned threads() const { return static_cast<unsigned>(workers_.size()); }

    // Queues the task's blocks. Returns false, queuing nothing, when max_pending tasks are
    // already waiting for a worker.
    bool submit(const std::shared_ptr<Task>& task);

    PoolStats stats() const;

private:
    void work();

    const std::size_t max_pending_;
    mutable std::mutex mutex_;
    std::condition_variable ready_;
    std::deque<std::shared_ptr<Task>> queue_;
    bool stopping_ = false;
    PoolStats stats_;
    std::vector<std::jthread> workers_;
};

}  // namespace superball::serve
