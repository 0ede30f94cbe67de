#include "root_acts.hpp"

namespace superball {

void throw_everywhere(const mpi::Comm& comm, const std::optional<Failure>& failure)
{
    // 0: none, 1: a failure, 2: bad input.
    const std::int64_t kind = comm.broadcast(std::int64_t{!failure ? 0 : failure->input ? 2 : 1});
    if (kind == 0) return;
    std::string message = failure ? failure->message : std::string();
    comm.broadcast(message);
    if (kind == 2) throw InputError(message);
    throw mpi::CollectiveError(message);
}

}  // namespace superball
