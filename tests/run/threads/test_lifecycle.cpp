// The lifecycle suite (tests/run/lifecycle_suite.hpp) over a team of threads in a process
// that never initialises MPI (the Python module's case: nothing of the run may call MPI).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "run/explore_threads.hpp"
#include "../../temp_dir.hpp"
#include "../lifecycle_suite.hpp"

namespace superball::test_support {
namespace {

struct OnThreads {
    TempDir dir{"superball-lifecycle"};
    std::filesystem::path operator/(const std::string& name) const { return dir / name; }
    RunSummary run(const Job& job, const ExploreSettings& s, RunObserver& observer, const StopRequested& stop,
                   unsigned threads)
    {
        return run_explore_threads(job, s, threads, observer, stop);
    }
    bool root() const { return true; }
    void sync() const {}
    int ranks() const { return 1; }
    int threads(unsigned asked) const { return static_cast<int>(asked); }
};

INSTANTIATE_TYPED_TEST_SUITE_P(Threads, Lifecycle, OnThreads);

}  // namespace
}  // namespace superball::test_support
