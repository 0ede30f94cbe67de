// main() of test_runs: Google Test under MPI. Every rank runs every test (the tests are
// collective); rank 0 prints the usual report, the other ranks only their failures, and
// a failure on any rank fails every process.
//
//   mpiexec -n 3 --oversubscribe build/release/tests/test_runs [--gtest_filter=...]
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdio>

#include "mpi/mpi.hpp"

namespace {

// The failures of a rank other than 0, which prints nothing else.
class FailurePrinter final : public testing::EmptyTestEventListener {
public:
    explicit FailurePrinter(int rank) : rank_(rank) {}
    void OnTestPartResult(const testing::TestPartResult& r) override
    {
        if (!r.failed()) return;
        std::fprintf(stderr, "[rank %d] %s:%d: Failure\n%s\n", rank_, r.file_name() ? r.file_name() : "?",
                     r.line_number(), r.summary());
    }

private:
    int rank_;
};

}  // namespace

int main(int argc, char** argv)
{
    testing::InitGoogleTest(&argc, argv);
    int failed = 0;
    {
        const superball::mpi::Environment env;
        const int rank = superball::mpi::Comm::world().rank();
        testing::TestEventListeners& listeners = testing::UnitTest::GetInstance()->listeners();
        if (rank != 0) {
            // Google Test owns its listeners: Release hands one back to delete, Append takes one.
            delete listeners.Release(listeners.default_result_printer());
            listeners.Append(new FailurePrinter(rank));
        }
        const int mine = RUN_ALL_TESTS() == 0 ? 0 : 1;
        superball::mpi::check(MPI_Allreduce(&mine, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
        if (rank == 0 && failed && !mine) std::fprintf(stderr, "test_runs: a test failed on another rank\n");
    }
    return failed;
}
