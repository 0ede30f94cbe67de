#include "schedule.hpp"

#include <time.h>

#include <algorithm>

namespace superball {

namespace {

// Up: a served rank to its server; down: a server to a rank it serves. Each level of the
// tree has a communicator of its own (the node's, the leaders'), so tags never meet.
constexpr int tag_up = 21;
constexpr int tag_down = 22;
// Aside: a node leader to the leader that writes its node's tiles, on the leaders'.
constexpr int tag_aside = 23;
// MPI_Comm_create_group's tags for the nodes' and the leaders' communicators.
constexpr int tag_node_group = 24;
constexpr int tag_leaders_group = 25;

// Which ranks serve which: the node (every rank of `comm` when one level is enough) and
// the node leaders, rank 0 first.
struct Topology {
    mpi::OwnedComm node;
    mpi::OwnedComm leaders;  // null on ranks that lead no node
    bool two_level = false;
    int nodes = 1;
};

Topology make_topology(const mpi::Comm& comm, const ScheduleSettings& s)
{
    Topology t;
    const int rank = comm.rank();
    const int size = comm.size();
    const int per_node = s.node_ranks;
    int nodes = 0;
    int biggest = 0;
    if (per_node > 0) {
        // Pseudo-nodes are runs of consecutive ranks, so every rank knows its node, the
        // node count and the leaders without a message: each communicator is made by its
        // own ranks alone. (A split gathers every rank's colour at rank 0, which SMPI
        // simulates at a cost growing as the square of the ranks: 16384 ranks never left it.)
        const int first = rank / per_node * per_node;
        t.node = mpi::OwnedComm::range(comm, first, std::min(first + per_node, size) - 1, 1, tag_node_group);
        nodes = (size + per_node - 1) / per_node;
        biggest = std::min(per_node, size);
    } else {
        // Key = rank: rank 0 leads its node, and every node's ranks keep their order.
        t.node = mpi::OwnedComm::split_shared(comm, rank);
        nodes = static_cast<int>(comm.sum({t.node.view().rank() == 0 ? 1u : 0u})[0]);
        biggest = static_cast<int>(comm.max(static_cast<double>(t.node.view().size())));
    }
    // One rank per node gains nothing from a leader: every rank is then served by rank 0.
    t.two_level = nodes > 1 && biggest > 1;
    t.nodes = t.two_level ? nodes : 1;
    if (!t.two_level) t.node = mpi::OwnedComm::dup(comm);
    const bool leads = t.node.view().rank() == 0;
    if (per_node == 0)
        t.leaders = mpi::OwnedComm::split(comm, leads ? 0 : MPI_UNDEFINED, rank);
    else if (leads)  // every node's first rank; rank 0 alone on one level
        t.leaders = mpi::OwnedComm::range(comm, 0, t.two_level ? size - 1 : 0, per_node, tag_leaders_group);
    return t;
}

PoolPlace place_of(const mpi::Comm& comm, const Topology& t)
{
    const mpi::Comm node = t.node.view();
    PoolPlace p;
    p.rank = comm.rank();
    p.ranks = comm.size();
    p.two_level = t.two_level;
    p.node_rank = node.rank();
    p.node_size = node.size();
    p.leaders = t.nodes;
    p.leader_rank = t.leaders.get() != MPI_COMM_NULL ? t.leaders.view().rank() : 0;
    return p;
}

// The pool's messages as MPI point-to-point messages of 64-bit words, on the node's and
// the leaders' communicators; its clock MPI_Wtime.
class MpiLinks final : public PoolLinks {
public:
    MpiLinks(const Topology& t, bool root)
        : node_(t.node.get()), leaders_(t.leaders.get()),
          parent_(root ? MPI_COMM_NULL : (t.node.view().rank() == 0 ? leaders_ : node_))
    {
    }

    double now() override { return MPI_Wtime(); }

    // nanosleep: under SMPI it is simulated time.
    void pause(double seconds) override
    {
        timespec ts{0, static_cast<long>(seconds * 1e9)};
        nanosleep(&ts, nullptr);
    }

    void send_up(std::span<const std::uint64_t> words) override { send(words, 0, tag_up, parent_); }

    void send_down(Peer to, std::span<const std::uint64_t> words) override
    {
        send(words, to.rank, tag_down, to.level == Level::node ? node_ : leaders_);
    }

    std::optional<int> receive_up(Level level, std::vector<std::uint64_t>& words) override
    {
        return receive_any(tag_up, level == Level::node ? node_ : leaders_, words);
    }

    void send_aside(int leader, std::span<const std::uint64_t> words) override { send(words, leader, tag_aside, leaders_); }

    bool receive_aside(std::vector<std::uint64_t>& words) override
    {
        return leaders_ != MPI_COMM_NULL && receive_any(tag_aside, leaders_, words).has_value();
    }

    bool receive_down(std::span<std::uint64_t> words, bool wait) override
    {
        if (!wait) {
            int waiting = 0;
            mpi::check(MPI_Iprobe(0, tag_down, parent_, &waiting, MPI_STATUS_IGNORE), "MPI_Iprobe");
            if (!waiting) return false;
        }
        mpi::check(MPI_Recv(words.data(), static_cast<int>(words.size()), MPI_UINT64_T, 0, tag_down, parent_,
                            MPI_STATUS_IGNORE),
                   "MPI_Recv");
        return true;
    }

private:
    // The next message with `tag` on `comm`, whatever its size, and its sender.
    static std::optional<int> receive_any(int tag, MPI_Comm comm, std::vector<std::uint64_t>& words)
    {
        int waiting = 0;
        MPI_Status st;
        mpi::check(MPI_Iprobe(MPI_ANY_SOURCE, tag, comm, &waiting, &st), "MPI_Iprobe");
        if (!waiting) return std::nullopt;
        int n = 0;
        mpi::check(MPI_Get_count(&st, MPI_UINT64_T, &n), "MPI_Get_count");
        words.resize(static_cast<std::size_t>(n));
        mpi::check(MPI_Recv(words.data(), n, MPI_UINT64_T, st.MPI_SOURCE, tag, comm, MPI_STATUS_IGNORE), "MPI_Recv");
        return st.MPI_SOURCE;
    }

    static void send(std::span<const std::uint64_t> words, int to, int tag, MPI_Comm comm)
    {
        mpi::check(MPI_Send(words.data(), static_cast<int>(words.size()), MPI_UINT64_T, to, tag, comm), "MPI_Send");
    }

    MPI_Comm node_;
    MPI_Comm leaders_;
    MPI_Comm parent_;  // the server is rank 0 of it
};

}  // namespace

ScheduleResult run_schedule(const mpi::Comm& comm, std::span<const ListedTile> pending, TileWork& work,
                            const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings,
                            const Writers& writers)
{
    const Topology topo = make_topology(comm, settings);
    MpiLinks links(topo, comm.is_root());
    PoolResult r = run_pool(links, place_of(comm, topo), pending, work, done, stop, settings, writers);
    const std::int64_t interrupted = comm.is_root() && r.unfinished ? 1 : 0;
    return {comm.broadcast(interrupted) != 0, std::move(r.stats)};
}

int schedule_writers(const mpi::Comm& comm, const ScheduleSettings& settings)
{
    return writer_count(place_of(comm, make_topology(comm, settings)), settings);
}

}  // namespace superball
