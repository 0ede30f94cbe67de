#include "pool.hpp"

namespace superball::serve {

Task::Task(std::size_t blocks, std::function<void(std::size_t)> run, Clock::time_point deadline)
    : blocks_(blocks), run_(std::move(run)), deadline_(deadline)
{
}

Task::Status Task::wait_for(std::chrono::milliseconds timeout)
{
    std::unique_lock lock(mutex_);
    if (!finished_cv_.wait_for(lock, timeout, [&] { return finished_ == blocks_; })) return Status::running;
    if (error_) return Status::failed;
    if (cancelled_) return Status::cancelled;
    if (timed_out_) return Status::timed_out;
    return Status::done;
}

std::exception_ptr Task::error() const
{
    std::lock_guard lock(mutex_);
    return error_;
}

Task::BlockResult Task::run_block(std::size_t b)
{
    bool run = false;
    {
        std::lock_guard lock(mutex_);
        if (!error_ && !cancelled_ && !timed_out_ && Clock::now() > deadline_) timed_out_ = true;
        run = !error_ && !cancelled_ && !timed_out_;
    }
    if (run) {
        try {
            run_(b);
        } catch (...) {
            std::lock_guard lock(mutex_);
            error_ = std::current_exception();
        }
    }
    std::lock_guard lock(mutex_);
    BlockResult r{run, ++finished_ == blocks_, cancelled_, timed_out_ && !cancelled_};
    if (r.last) finished_cv_.notify_all();
    return r;
}

Pool::Pool(unsigned threads, std::size_t max_pending) : max_pending_(max_pending)
{
    for (unsigned k = 0; k < threads; ++k) workers_.emplace_back([this] { work(); });
}

Pool::~Pool()
{
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
        for (const auto& task : queue_) task->cancel();
    }
    ready_.notify_all();
    workers_.clear();  // joins
}

bool Pool::submit(const std::shared_ptr<Task>& task)
{
    {
        std::lock_guard lock(mutex_);
        if (queue_.size() >= max_pending_) {
            ++stats_.refused;
            return false;
        }
        ++stats_.tasks;
        if (task->blocks_ == 0) return true;
        queue_.push_back(task);
    }
    ready_.notify_all();
    return true;
}

PoolStats Pool::stats() const
{
    std::lock_guard lock(mutex_);
    PoolStats s = stats_;
    s.pending = queue_.size();
    return s;
}

void Pool::work()
{
    for (;;) {
        std::shared_ptr<Task> task;
        std::size_t b = 0;
        {
            std::unique_lock lock(mutex_);
            ready_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
            if (queue_.empty()) return;
            task = queue_.front();
            queue_.pop_front();
            b = task->next_++;
            // Round robin: the task goes to the back with its remaining blocks.
            if (task->next_ < task->blocks_) queue_.push_back(task);
        }
        const Task::BlockResult r = task->run_block(b);
        std::lock_guard lock(mutex_);
        ++(r.run ? stats_.blocks_run : stats_.blocks_skipped);
        stats_.cancelled += r.last && r.cancelled;
        stats_.timed_out += r.last && r.timed_out;
    }
}

}  // namespace superball::serve
