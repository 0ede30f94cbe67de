// Small RAII layer over the MPI calls superball makes: the environment, communicators and
// the few collectives the runs need. No other project code: io/ and run/ build on it.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
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

// Open MPI parameters for a run on one node, decided from the environment before MPI_Init
// (names without the OMPI_MCA_ prefix, with their values). Open MPI's default start-up
// opens its network transports (UCX, the PSM/PSM2 libraries of the cm layer) whether or not
// there is a network, and a singleton (a process started without mpirun) first starts a
// daemon of its own: together 0.2-0.3 s of a 0.35 s job on the 2-core test machine.
//   pml = ob1                     (shared memory between the ranks, TCP: all one node
//                                 needs) for a singleton and for an Open MPI mpirun whose
//                                 ranks are all on this node (OMPI_COMM_WORLD_LOCAL_SIZE =
//                                 OMPI_COMM_WORLD_SIZE);
//   ess_singleton_isolated = 1    (no daemon: superball never spawns or connects to other
//                                 processes) for a singleton.
// A parameter the user set is left alone: OMPI_MCA_<name> in the environment, even set to
// nothing (also how `mpirun --mca NAME VALUE` reaches the ranks), or a line in
// `user_params`, the text of ~/.openmpi/mca-params.conf; and nothing is set when other
// parameter files are named (OMPI_MCA_mca_base_param_files), when the ranks span several
// nodes (InfiniBand or Omni-Path is then what they need), or when another launcher started
// the process (srun, MPICH's hydra: PMI or PMIx variables without Open MPI's), which says
// nothing here about the number of nodes.
struct McaSetting {
    std::string name;
    std::string value;
    friend bool operator==(const McaSetting&, const McaSetting&) = default;
};
using Getenv = std::function<const char*(const char* name)>;
std::vector<McaSetting> single_node_mca(const Getenv& getenv, std::string_view user_params);

// MPI_Init / MPI_Finalize for the lifetime of the object. One per process. With Open MPI,
// sets the parameters of single_node_mca() first. An isolated singleton also gets a session
// directory of its own (orte_tmpdir_base, a fresh directory under $TMPDIR or /tmp, removed
// after MPI_Finalize): isolated singletons all take the job family 0, so two started at the
// same moment create and remove the same <tmp>/ompi.<host>.<uid>/jf.0 and one of them fails
// in orte_init ("A call to mkdir was unable to create the desired directory", ompi#3818).
class Environment {
public:
    Environment();
    ~Environment();
    Environment(const Environment&) = delete;
    Environment& operator=(const Environment&) = delete;

private:
    // A directory removed, with what is in it, when the object goes: after MPI_Finalize
    // (members outlive the destructor's body), and on every way out of a failed start.
    class PrivateDirectory {
    public:
        explicit PrivateDirectory(std::string path) : path_(std::move(path)) {}
        ~PrivateDirectory();
        PrivateDirectory(const PrivateDirectory&) = delete;
        PrivateDirectory& operator=(const PrivateDirectory&) = delete;

    private:
        std::string path_;
    };
    std::optional<PrivateDirectory> session_base_;
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
    // Element-wise largest value over ranks, on every rank.
    std::vector<std::int32_t> max(const std::vector<std::int32_t>& v) const;
    // Every rank's values concatenated in rank order, on rank 0 (empty elsewhere).
    std::vector<double> gather(const std::vector<double>& mine) const;
    // Point to point: `v` to rank `to`, and the `n` values rank `from` sends with the same
    // `tag` (blocking both).
    void send(const std::vector<std::uint64_t>& v, int to, int tag) const;
    std::vector<std::uint64_t> receive(std::size_t n, int from, int tag) const;

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
    // MPI_Comm_create_group over the ranks first, first + stride, ... up to last of `c`:
    // collective over those ranks only (a split is collective over all of `c`), so each
    // rank must call it for the group it belongs to, with the same `tag` per group.
    static OwnedComm range(const Comm& c, int first, int last, int stride, int tag);
    static OwnedComm dup(const Comm& c);

    bool null() const { return comm_ == MPI_COMM_NULL; }
    MPI_Comm get() const { return comm_; }
    Comm view() const { return Comm(comm_); }

private:
    explicit OwnedComm(MPI_Comm c) : comm_(c) {}
    MPI_Comm comm_ = MPI_COMM_NULL;
};

// The number of hosts (shared-memory nodes, MPI_Comm_split_type) the ranks of `c` run on,
// on every rank. Collective.
int host_count(const Comm& c);

}  // namespace superball::mpi
