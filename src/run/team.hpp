// Who runs an exploration: the ranks of an MPI communicator, or the threads of this one
// process (no MPI at all: the Python module). A run's lifecycle (run/lifecycle.hpp) is one
// algorithm over either team; what its collectives come to is said here once. A team of one
// process has nobody to tell: its collectives return what they are given.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mpi/mpi.hpp"
#include "run/root_acts.hpp"

namespace superball {

class Team {
public:
    // Every rank of `comm` (which must outlive the team), each counting on one thread.
    static Team ranks(const mpi::Comm& comm) { return Team(&comm, 1); }
    // This process alone, counting on `threads` threads (at least 1).
    static Team threads(unsigned threads) { return Team(nullptr, threads < 1 ? 1 : threads); }

    // The communicator of a team of ranks; nullptr for one process.
    const mpi::Comm* comm() const { return comm_; }
    // The process that owns the run's files and records it: rank 0, or this one.
    bool is_root() const { return comm_ == nullptr || comm_->is_root(); }
    int rank() const { return comm_ ? comm_->rank() : 0; }
    int processes() const { return comm_ ? comm_->size() : 1; }
    // Counting threads per process.
    unsigned threads_each() const { return threads_; }
    // How many count at once (ranks, or threads): a new run's tiles are cut for them.
    int counters() const { return processes() * static_cast<int>(threads_); }
    int hosts() const { return comm_ ? mpi::host_count(*comm_) : 1; }

    // Collective, like the MPI calls they make in a team of ranks.
    void barrier() const
    {
        if (comm_) comm_->barrier();
    }
    // The root's value on every process.
    std::string broadcast(std::string s) const;
    std::vector<std::uint64_t> broadcast(std::vector<std::uint64_t> v) const;
    std::int64_t broadcast(std::int64_t x) const { return comm_ ? comm_->broadcast(x) : x; }
    double broadcast(double x) const { return comm_ ? comm_->broadcast(x) : x; }
    // Element-wise sum, and largest value, over the processes, on every one.
    std::vector<std::uint64_t> sum(std::vector<std::uint64_t> v) const { return comm_ ? comm_->sum(v) : v; }
    double max(double x) const { return comm_ ? comm_->max(x) : x; }
    // Every process's `mine`, concatenated in rank order, on every process.
    std::vector<std::uint64_t> all_of(const std::vector<std::uint64_t>& mine) const;
    // Point to point, between the ranks of a team of several (a team of one process has no
    // other: std::logic_error).
    void send(const std::vector<std::uint64_t>& words, int to, int tag) const;
    std::vector<std::uint64_t> receive(std::size_t n, int from, int tag) const;

    // The root's `failure` (the others pass theirs, ignored) thrown on every process: as
    // InputError if it was bad input, else as RunError (mpi::CollectiveError); nothing if
    // the root met none.
    void throw_everywhere(const std::optional<Failure>& failure) const;
    // The root runs `act`; then every process throws what it threw.
    template <class Act>
    void root_acts(Act&& act) const
    {
        throw_everywhere(is_root() ? attempt(std::forward<Act>(act)) : std::nullopt);
    }

private:
    Team(const mpi::Comm* comm, unsigned threads) : comm_(comm), threads_(threads) {}

    const mpi::Comm* comm_;
    unsigned threads_;
};

}  // namespace superball
