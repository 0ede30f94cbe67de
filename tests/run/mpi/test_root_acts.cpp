// Rank 0 acts alone and every rank learns the outcome (run/root_acts.hpp), under MPI at
// whatever rank count the test runs with (ctest: 1 to 4): what rank 0 throws is thrown on
// every rank, of the same kind and with the same words; what another rank throws is not
// its to report; the ranks stay in step (a barrier after each case).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "run/root_acts.hpp"
#include "shared_dir.hpp"

namespace superball {
namespace {

using test_support::world;

TEST(RootActs, NothingThrownWhenRankZeroSucceeds)
{
    int acted = 0;
    EXPECT_NO_THROW(root_acts(world, [&] { ++acted; }));
    EXPECT_EQ(acted, world.is_root() ? 1 : 0);
    world.barrier();
}

TEST(RootActs, BadInputOnRankZeroIsBadInputEverywhere)
{
    try {
        root_acts(world, [] { throw InputError("rank 0 refused this"); });
        ADD_FAILURE() << "nothing thrown on rank " << world.rank();
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "rank 0 refused this");
    }
    world.barrier();
}

TEST(RootActs, AnyOtherFailureIsARunErrorEverywhere)
{
    try {
        root_acts(world, [] { throw std::runtime_error("the file system is full"); });
        ADD_FAILURE() << "nothing thrown on rank " << world.rank();
    } catch (const mpi::CollectiveError& e) {
        EXPECT_STREQ(e.what(), "the file system is full");
    }
    world.barrier();
}

TEST(ThrowEverywhere, OnlyRankZerosFailureCounts)
{
    // Every rank but 0 says it failed: no rank throws.
    const std::optional<Failure> mine =
        world.is_root() ? std::nullopt : std::optional<Failure>(Failure{"rank " + std::to_string(world.rank()), false});
    EXPECT_NO_THROW(throw_everywhere(world, mine));
    // Rank 0's attempt, caught and reworded before every rank learns it.
    std::optional<Failure> failure;
    if (world.is_root()) failure = attempt([] { throw std::runtime_error("disk"); });
    if (failure) failure->message = "finishing failed: " + failure->message;
    EXPECT_THROW(
        {
            try {
                throw_everywhere(world, failure);
            } catch (const mpi::CollectiveError& e) {
                EXPECT_STREQ(e.what(), "finishing failed: disk");
                throw;
            }
        },
        mpi::CollectiveError);
    world.barrier();
}

}  // namespace
}  // namespace superball
