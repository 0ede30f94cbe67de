#include "every_rank.hpp"

#include <fmt/core.h>

#include <exception>

#include "core/input.hpp"

namespace superball::cli {

int on_every_rank(std::string_view command, const mpi::Comm& world, const std::function<int()>& body)
{
    try {
        return body();
    } catch (const InputError& e) {
        if (world.is_root()) fmt::print(stderr, "superball {}: {}\n", command, e.what());
        return 2;
    } catch (const mpi::CollectiveError& e) {
        if (world.is_root()) fmt::print(stderr, "superball {}: error: {}\n", command, e.what());
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "superball {} (rank {}): error: {}\n", command, world.rank(), e.what());
        world.abort(1);
    }
}

}  // namespace superball::cli
