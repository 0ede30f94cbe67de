// A machine of many ranks inside one process, for the work pool (run/work_pool.hpp): every
// rank is a thread, but only one runs at a time, always the one whose clock is the
// earliest (a discrete-event simulation, as SimGrid runs MPI programs): the outcome of a
// run is the same whatever the load of the machine the test runs on, and a test of tile
// costs in seconds takes milliseconds. Messages arrive `latency` seconds after they are
// sent, in the order sent. A run that can go no further (every rank waiting for a message
// that will not come) fails instead of hanging.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "run/work_pool.hpp"

namespace superball::testing {

class FakeMachine {
public:
    struct Options {
        int ranks = 4;
        int node_ranks = 0;       // > 0: nodes of that many consecutive ranks (as ScheduleSettings::node_ranks)
        double latency = 2e-6;    // seconds from a send to its arrival
        double time_limit = 1e5;  // a clock past this is a runaway run: the run fails
    };

    // Thrown out of every rank's waits and clock advances once the machine is lost (lose_all_at)
    // or the run failed elsewhere.
    struct Ended {};

    explicit FakeMachine(Options o) : o_(o), ranks_(static_cast<std::size_t>(o.ranks))
    {
        const int per = o.node_ranks > 0 ? o.node_ranks : o.ranks;
        const int nodes = (o.ranks + per - 1) / per;
        // As run_schedule's topology: one rank per node, or one node, needs no leaders.
        two_level_ = nodes > 1 && per > 1;
        node_of_ = two_level_ ? per : o.ranks;
    }

    PoolPlace place(int rank) const
    {
        PoolPlace p;
        p.rank = rank;
        p.ranks = o_.ranks;
        p.two_level = two_level_;
        p.node_rank = rank % node_of_;
        p.node_size = std::min(node_of_, o_.ranks - rank / node_of_ * node_of_);
        p.leaders = two_level_ ? (o_.ranks + node_of_ - 1) / node_of_ : 1;
        p.leader_rank = p.node_rank == 0 ? rank / node_of_ : 0;
        return p;
    }

    // From time `at` on the machine is lost, as an MPI job is when one of its nodes dies:
    // every rank ends (Ended) the moment its clock would pass `at`.
    void lose_all_at(double at) { lose_at_ = at; }
    bool lost() const { return lost_; }

    // Runs body(rank, links) on every rank until every one has returned or ended. Rethrows
    // what a rank threw (but Ended), or reports a run that could go no further.
    void run(const std::function<void(int, PoolLinks&)>& body)
    {
        std::vector<std::thread> threads;
        for (int r = 0; r < o_.ranks; ++r) threads.emplace_back([this, r, &body] { rank_main(r, body); });
        {
            const std::lock_guard<std::mutex> guard(mutex_);
            hand_over(pick());
        }
        for (std::thread& t : threads) t.join();
        if (error_) std::rethrow_exception(error_);
    }

    // The rank spends `seconds` computing: ranks whose clocks are earlier run meanwhile.
    void spend(int rank, double seconds)
    {
        std::unique_lock<std::mutex> lock(mutex_);
        advance(rank, seconds, lock);
    }

    double clock(int rank) const { return ranks_[static_cast<std::size_t>(rank)].t; }

private:
    struct Message {
        double at = 0;  // arrival
        int from = 0;   // the sender's rank at the level it was sent on
        std::vector<std::uint64_t> words;
    };
    struct Rank {
        double t = 0;
        bool waiting = false;  // for a message from its server
        bool done = false;
        std::deque<Message> up[2];  // from the ranks it serves, by Level
        std::deque<Message> down;   // from its server
        std::deque<Message> aside;  // from other node leaders
        std::condition_variable turn;  // its turn came, or the run ended
    };

    class Links final : public PoolLinks {
    public:
        Links(FakeMachine& m, int rank) : m_(m), rank_(rank) {}
        double now() override { return m_.clock(rank_); }
        void pause(double seconds) override { m_.spend(rank_, seconds); }
        void send_up(std::span<const std::uint64_t> words) override { m_.send_up(rank_, words); }
        void send_down(Peer to, std::span<const std::uint64_t> words) override { m_.send_down(rank_, to, words); }
        std::optional<int> receive_up(Level level, std::vector<std::uint64_t>& words) override
        {
            return m_.receive_up(rank_, level, words);
        }
        bool receive_down(std::span<std::uint64_t> words, bool wait) override
        {
            return m_.receive_down(rank_, words, wait);
        }
        void send_aside(int leader, std::span<const std::uint64_t> words) override { m_.send_aside(rank_, leader, words); }
        bool receive_aside(std::vector<std::uint64_t>& words) override { return m_.receive_aside(rank_, words); }

    private:
        FakeMachine& m_;
        int rank_;
    };

    Rank& at(int rank) { return ranks_[static_cast<std::size_t>(rank)]; }

    void rank_main(int rank, const std::function<void(int, PoolLinks&)>& body)
    {
        std::unique_lock<std::mutex> lock(mutex_);
        at(rank).turn.wait(lock, [&] { return turn_ == rank || ended_; });
        if (!ended_) {
            lock.unlock();
            try {
                Links links(*this, rank);
                body(rank, links);
            } catch (const Ended&) {
            } catch (...) {
                const std::lock_guard<std::mutex> guard(mutex_);
                fail(std::current_exception());
            }
            lock.lock();
        }
        at(rank).done = true;
        if (!ended_) hand_over(pick());
    }

    // The rank to run next: the earliest clock among those that can run (a rank waiting
    // for its server, from the arrival of its next message), the lowest rank on a tie.
    int pick()
    {
        int best = -1;
        double best_t = std::numeric_limits<double>::infinity();
        bool any_left = false;
        for (int r = 0; r < o_.ranks; ++r) {
            const Rank& k = at(r);
            if (k.done) continue;
            any_left = true;
            double t = k.t;
            if (k.waiting) {
                if (k.down.empty()) continue;
                t = std::max(t, k.down.front().at);
            }
            if (t < best_t) {
                best_t = t;
                best = r;
            }
        }
        if (best < 0 && any_left) {
            fail(std::make_exception_ptr(std::runtime_error("fake machine: every rank waits for a message that will not come")));
        }
        return best;
    }

    // Hands the turn to the rank that should run next and waits for it to come back.
    void yield(int rank, std::unique_lock<std::mutex>& lock)
    {
        const int next = pick();
        if (next == rank && !ended_) return;
        hand_over(next);
        at(rank).turn.wait(lock, [&] { return turn_ == rank || ended_; });
        if (ended_) throw Ended{};
    }

    void advance(int rank, double seconds, std::unique_lock<std::mutex>& lock)
    {
        if (ended_) throw Ended{};
        Rank& k = at(rank);
        if (k.t + seconds > lose_at_) {
            lost_ = true;
            end();
            throw Ended{};
        }
        k.t += seconds;
        if (k.t > o_.time_limit) {
            fail(std::make_exception_ptr(std::runtime_error("fake machine: a clock ran past the time limit")));
            throw Ended{};
        }
        yield(rank, lock);
    }

    void fail(std::exception_ptr e)
    {
        if (!error_) error_ = std::move(e);
        end();
    }

    // Wakes only the rank whose turn it is: with every rank woken at each turn, 32 ranks
    // spent seconds in the kernel.
    void hand_over(int next)
    {
        turn_ = next;
        if (next >= 0) at(next).turn.notify_one();
    }

    void end()
    {
        ended_ = true;
        for (Rank& k : ranks_) k.turn.notify_all();
    }

    void deliver(std::deque<Message>& box, int from, double t, std::span<const std::uint64_t> words)
    {
        box.push_back({t + o_.latency, from, {words.begin(), words.end()}});
    }

    void send_up(int rank, std::span<const std::uint64_t> words)
    {
        const std::lock_guard<std::mutex> guard(mutex_);
        const PoolPlace p = place(rank);
        // A node leader (not rank 0) reports to rank 0 as a leader; any other rank to its leader.
        if (two_level_ && p.node_rank == 0) {
            deliver(at(0).up[static_cast<int>(Level::leaders)], rank / node_of_, at(rank).t, words);
        } else {
            deliver(at(rank - p.node_rank).up[static_cast<int>(Level::node)], p.node_rank, at(rank).t, words);
        }
    }

    void send_down(int rank, Peer to, std::span<const std::uint64_t> words)
    {
        const std::lock_guard<std::mutex> guard(mutex_);
        const int dest = to.level == Level::leaders ? to.rank * node_of_ : rank + to.rank;
        deliver(at(dest).down, 0, at(rank).t, words);
    }

    void send_aside(int rank, int leader, std::span<const std::uint64_t> words)
    {
        const std::lock_guard<std::mutex> guard(mutex_);
        deliver(at(leader * node_of_).aside, rank / node_of_, at(rank).t, words);
    }

    bool receive_aside(int rank, std::vector<std::uint64_t>& words)
    {
        const std::lock_guard<std::mutex> guard(mutex_);
        std::deque<Message>& box = at(rank).aside;
        if (box.empty() || box.front().at > at(rank).t) return false;
        words = std::move(box.front().words);
        box.pop_front();
        return true;
    }

    std::optional<int> receive_up(int rank, Level level, std::vector<std::uint64_t>& words)
    {
        const std::lock_guard<std::mutex> guard(mutex_);
        std::deque<Message>& box = at(rank).up[static_cast<int>(level)];
        if (box.empty() || box.front().at > at(rank).t) return std::nullopt;
        words = std::move(box.front().words);
        const int from = box.front().from;
        box.pop_front();
        return from;
    }

    bool receive_down(int rank, std::span<std::uint64_t> words, bool wait)
    {
        std::unique_lock<std::mutex> lock(mutex_);
        Rank& k = at(rank);
        if (!wait && (k.down.empty() || k.down.front().at > k.t)) return false;
        if (k.down.empty() || k.down.front().at > k.t) {
            // Waits: the ranks whose clocks are earlier than the message's arrival run first.
            k.waiting = true;
            try {
                yield(rank, lock);
            } catch (const Ended&) {
                k.waiting = false;
                throw;
            }
            k.waiting = false;
            if (k.down.empty()) throw std::logic_error("fake machine: a waiting rank ran with no message");
            k.t = std::max(k.t, k.down.front().at);
        }
        const std::vector<std::uint64_t>& w = k.down.front().words;
        if (w.size() != words.size()) throw std::logic_error("fake machine: a message from the server of the wrong size");
        std::copy(w.begin(), w.end(), words.begin());
        k.down.pop_front();
        return true;
    }

    Options o_;
    std::vector<Rank> ranks_;
    bool two_level_ = false;
    int node_of_ = 1;  // ranks per node (every rank with one level)
    double lose_at_ = std::numeric_limits<double>::infinity();
    bool lost_ = false;

    std::mutex mutex_;
    int turn_ = -1;
    bool ended_ = false;
    std::exception_ptr error_;
};

// The tiles 0 .. n-1 in order: a hand-out list.
inline std::vector<ListedTile> listed_tiles(std::uint64_t n)
{
    std::vector<ListedTile> v(n);
    std::iota(v.begin(), v.end(), 0);
    return v;
}

// The checksum the fake work gives a tile (any function of the tile that the record can check).
inline std::uint64_t checksum_of(std::uint64_t tile) { return tile * 0x9E3779B97F4A7C15ull + 1; }

}  // namespace superball::testing
