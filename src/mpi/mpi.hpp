// Small RAII layer over the MPI calls superball makes: the environment, communicators and
// the few collectives the runs need. No other project code: io/ and run/ build on it.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace superball::mpi {

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

// A communicator made from another (split, dup) and freed with this object. Collective
// like the calls that make it; destroy it before MPI_Finalize.
class OwnedComm {
public:
    OwnedComm() = default;
    ~OwnedComm();
    OwnedComm(OwnedComm&& o) noexcept : comm_(o.comm_) { o.comm_ = MPI_COMM_NULL; }
    OwnedComm& operator=(OwnedComm&& o) noexcept;
    OwnedComm(const OwnedComm&) = delete;
    OwnedComm& operator=(const OwnedComm&) = delete;

    // MPI_Comm_split: ranks of equal `color` together, ordered by `key`; MPI_UNDEFINED
    // gives a null communicator.
    static OwnedComm split(const Comm& c, int color, int key);
    // MPI_Comm_split_type(MPI_COMM_TYPE_SHARED): the ranks that share this rank's memory
    // (its node), ordered by `key`.
    static OwnedComm split_shared(const Comm& c, int key);
    static OwnedComm dup(const Comm& c);

    bool null() const { return comm_ == MPI_COMM_NULL; }
    MPI_Comm get() const { return comm_; }
    Comm view() const { return Comm(comm_); }

private:
    explicit OwnedComm(MPI_Comm c) : comm_(c) {}
    MPI_Comm comm_ = MPI_COMM_NULL;
};

}  // namespace superball::mpi
