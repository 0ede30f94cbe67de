// "Rank 0 acts, every rank learns the outcome": rank 0 alone does something (makes or reads
// a file), and a failure it meets must reach every rank, which would otherwise wait for it
// in the next collective for ever. Kept in one place: a broadcast forgotten on one path hangs
// a whole job.
#pragma once

#include <exception>
#include <optional>
#include <string>
#include <utility>

#include "core/input.hpp"
#include "mpi/mpi.hpp"

namespace superball {

// What one rank met while acting alone: its message, and whether it was bad input
// (InputError, status 2) rather than a failure (status 1).
struct Failure {
    std::string message;
    bool input = false;
};

// Runs `act` on this rank; what it throws (a std::exception) is returned instead.
template <class Act>
std::optional<Failure> attempt(Act&& act)
{
    try {
        std::forward<Act>(act)();
    } catch (const InputError& e) {
        return Failure{e.what(), true};
    } catch (const std::exception& e) {
        return Failure{e.what(), false};
    }
    return std::nullopt;
}

// Collective: rank 0's `failure` (the others pass theirs, ignored) thrown on every rank, as
// InputError if it was bad input, else as RunError (mpi::CollectiveError); nothing if rank 0
// met none.
void throw_everywhere(const mpi::Comm& comm, const std::optional<Failure>& failure);

// Collective: rank 0 runs `act`, then every rank throws what it threw (throw_everywhere).
template <class Act>
void root_acts(const mpi::Comm& comm, Act&& act)
{
    throw_everywhere(comm, comm.is_root() ? attempt(std::forward<Act>(act)) : std::nullopt);
}

}  // namespace superball
