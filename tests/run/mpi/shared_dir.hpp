// What the tests under MPI share: the world communicator, and a scratch directory made by
// rank 0, the same path on every rank, removed at the end (after every rank is done with it).
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "mpi/mpi.hpp"

namespace superball::test_support {

// Every rank of the test's mpirun (a handle: no MPI call before MPI_Init).
inline const mpi::Comm world = mpi::Comm::world();

class SharedDir {
public:
    SharedDir()
    {
        std::string p;
        if (world.is_root()) {
            std::string templ = (std::filesystem::temp_directory_path() / "superball-runs-XXXXXX").string();
            p = mkdtemp(templ.data()) ? templ : "";
        }
        world.broadcast(p);
        if (p.empty()) throw std::runtime_error("mkdtemp failed");
        path_ = p;
    }
    ~SharedDir()
    {
        world.barrier();
        std::error_code ec;
        if (world.is_root()) std::filesystem::remove_all(path_, ec);
    }
    SharedDir(const SharedDir&) = delete;
    SharedDir& operator=(const SharedDir&) = delete;
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

}  // namespace superball::test_support
