// Small RAII layer over the MPI calls superball makes: the environment, communicators and
// the few collectives the runs need. No other project code: io/ and run/ build on it.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace superball::mpi {

// A failure that every rank of a communicator raises alike, so the ranks are still in step:
// the caller reports it once and exits normally (no MPI_Abort).
struct CollectiveError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Turns an MPI error code into an exception (MPI_ERRORS_RETURN is set on the world
// communicator by Environment).
void check(int code, const char* what);

// MPI_Init / MPI_Finalize for the lifetime of the object. One per process.
class Environment {
public:
    Environment();
    ~Environment();
    Environment(const Environment&) = delete;
    Environment& operator=(const Environment&) = delete;
};

// An MPI_Info object of hints (MPI-IO's, here), freed with the object.
class Info {
public:
    Info();
    ~Info();
    Info(const Info&) = delete;
    Info& operator=(const Info&) = delete;
    void set(const std::string& key, const std::string& value);
    MPI_Info get() const { return info_; }

private:
    MPI_Info info_ = MPI_INFO_NULL;
};

// A communicator borrowed from MPI (not freed here).
class Comm {
public:
    explicit Comm(MPI_Comm c) : comm_(c) {}
    static Comm world() { return Comm(MPI_COMM_WORLD); }

    MPI_Comm get() const { return comm_; }
    int rank() const;
    int size() const;
    bool is_root() const { return rank() == 0; }

    void barrier() const;
    // Rank 0's value on every rank.
    void broadcast(std::string& s) const;
    void broadcast(std::vector<std::uint64_t>& v) const;
    void broadcast(std::vector<double>& v) const;
    std::int64_t broadcast(std::int64_t x) const;
    double broadcast(double x) const;
    // Element-wise sum over ranks, result on every rank.
    std::vector<std::uint64_t> sum(const std::vector<std::uint64_t>& v) const;
    // Largest value over ranks, on every rank.
    double max(double x) const;
    // Every rank's values concatenated in rank order, on rank 0 (empty elsewhere).
    std::vector<double> gather(const std::vector<double>& mine) const;

    // Ends every process of the job: the only way out when one rank fails outside a
    // collective operation.
    [[noreturn]] void abort(int status) const;

private:
    MPI_Comm comm_;
};

}  // namespace superball::mpi
