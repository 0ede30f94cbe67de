#include "team.hpp"

#include <stdexcept>

namespace superball {

std::string Team::broadcast(std::string s) const
{
    if (comm_) comm_->broadcast(s);
    return s;
}

std::vector<std::uint64_t> Team::broadcast(std::vector<std::uint64_t> v) const
{
    if (comm_) comm_->broadcast(v);
    return v;
}

std::vector<std::uint64_t> Team::all_of(const std::vector<std::uint64_t>& mine) const
{
    if (!comm_) return mine;
    // Through doubles (mpi::Comm::gather): the values here are tile numbers, below 2^30
    // (job/tiles.hpp max_run_tiles), exact in a double.
    const std::vector<double> all = comm_->gather(std::vector<double>(mine.begin(), mine.end()));
    std::vector<std::uint64_t> out(all.begin(), all.end());
    comm_->broadcast(out);
    return out;
}

void Team::send(const std::vector<std::uint64_t>& words, int to, int tag) const
{
    if (!comm_) throw std::logic_error("Team::send: a team of one process has no rank " + std::to_string(to));
    comm_->send(words, to, tag);
}

std::vector<std::uint64_t> Team::receive(std::size_t n, int from, int tag) const
{
    if (!comm_) throw std::logic_error("Team::receive: a team of one process has no rank " + std::to_string(from));
    return comm_->receive(n, from, tag);
}

void Team::throw_everywhere(const std::optional<Failure>& failure) const
{
    if (comm_) {
        superball::throw_everywhere(*comm_, failure);
    } else if (failure) {
        if (failure->input) throw InputError(failure->message);
        throw mpi::CollectiveError(failure->message);
    }
}

}  // namespace superball
