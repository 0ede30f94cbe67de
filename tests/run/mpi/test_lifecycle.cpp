// The lifecycle suite (tests/run/lifecycle_suite.hpp) over a team of MPI ranks (run_explore
// on every rank of the test's mpirun, 1 to 4) and over a team of threads in each rank (each
// rank its own run in its own directory, as a Python user's process under mpirun would).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mpi/mpi.hpp"
#include "run/explore.hpp"
#include "../lifecycle_suite.hpp"
#include "shared_dir.hpp"

namespace superball::test_support {
namespace {

struct OnRanks {
    SharedDir dir;
    std::filesystem::path operator/(const std::string& name) const { return dir / name; }
    RunSummary run(const Job& job, const ExploreSettings& s, RunObserver& observer, const StopRequested& stop, unsigned)
    {
        return run_explore(job, s, world, observer, stop);
    }
    bool root() const { return world.is_root(); }
    void sync() const { world.barrier(); }
    int ranks() const { return world.size(); }
    int threads(unsigned) const { return 1; }
};

// OnThreads (lifecycle_suite.hpp): each rank its own run in its own directory.
using Teams = testing::Types<OnRanks, OnThreads>;
INSTANTIATE_TYPED_TEST_SUITE_P(Team, Lifecycle, Teams);

}  // namespace
}  // namespace superball::test_support
