// The communicators src/mpi/mpi.hpp makes from others, under MPI at whatever rank count the
// test runs with (ctest: 1 to 4): a range of ranks made by its own ranks alone (the
// schedule's pseudo-nodes and their leaders), a split, a copy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>

#include "mpi/mpi.hpp"
#include "shared_dir.hpp"

namespace superball {
namespace {

using test_support::world;

// Pseudo-nodes of two consecutive ranks (the last alone when the ranks are odd), each made
// by its two ranks only: each rank learns its place and the sum over its node is its own.
TEST(OwnedCommRange, ConsecutiveRanksMakeANodeOfTheirOwn)
{
    const int first = world.rank() / 2 * 2;
    const int last = std::min(first + 2, world.size()) - 1;
    const mpi::OwnedComm node = mpi::OwnedComm::range(world, first, last, 1, 7);
    ASSERT_FALSE(node.null());
    EXPECT_EQ(node.view().size(), last - first + 1);
    EXPECT_EQ(node.view().rank(), world.rank() - first);
    const std::uint64_t expected = static_cast<std::uint64_t>(first) + static_cast<std::uint64_t>(last);
    EXPECT_EQ(node.view().sum({static_cast<std::uint64_t>(world.rank())})[0],
              last > first ? expected : static_cast<std::uint64_t>(first));
}

// Every second rank from 0 (the leaders of nodes of two): only they call, the others hold
// no communicator; rank k of it is world rank 2k.
TEST(OwnedCommRange, AStrideMakesTheLeaders)
{
    mpi::OwnedComm leaders;
    if (world.rank() % 2 == 0) leaders = mpi::OwnedComm::range(world, 0, world.size() - 1, 2, 8);
    if (world.rank() % 2 != 0) {
        EXPECT_TRUE(leaders.null());
        return;
    }
    ASSERT_FALSE(leaders.null());
    EXPECT_EQ(leaders.view().size(), (world.size() + 1) / 2);
    EXPECT_EQ(leaders.view().rank(), world.rank() / 2);
    EXPECT_EQ(leaders.view().broadcast(static_cast<std::int64_t>(world.rank() == 0 ? 41 : 0)), 41);
}

// A split by the same pseudo-nodes gives each rank the same node as the range; a copy of
// the world the same places as the world.
TEST(OwnedComm, SplitAndDupAgreeWithRanges)
{
    const int first = world.rank() / 2 * 2;
    const mpi::OwnedComm range = mpi::OwnedComm::range(world, first, std::min(first + 2, world.size()) - 1, 1, 9);
    const mpi::OwnedComm split = mpi::OwnedComm::split(world, world.rank() / 2, world.rank());
    EXPECT_EQ(split.view().rank(), range.view().rank());
    EXPECT_EQ(split.view().size(), range.view().size());
    const mpi::OwnedComm copy = mpi::OwnedComm::dup(world);
    EXPECT_EQ(copy.view().rank(), world.rank());
    EXPECT_EQ(copy.view().size(), world.size());
}

}  // namespace
}  // namespace superball
