// The lifecycle suite (tests/run/lifecycle_suite.hpp) over a team of threads in a process
// that never initialises MPI (the Python module's case: nothing of the run may call MPI).
#include <gtest/gtest.h>

#include "../lifecycle_suite.hpp"

namespace superball::test_support {
namespace {

INSTANTIATE_TYPED_TEST_SUITE_P(Threads, Lifecycle, OnThreads);

}  // namespace
}  // namespace superball::test_support
