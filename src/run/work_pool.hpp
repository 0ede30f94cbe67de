// The work pool: how tiles are handed out to ranks, given back and recorded, one rank's
// part of it, over any transport (run_schedule in schedule.hpp runs it over MPI; the tests
// of tests/run/pool over a fake machine of one process with a clock of its own).
//
// The cost of a point varies by orders of magnitude across a grid (one bounce near the
// edges, up to max_bounces near self-similar motions), so tiles are handed out on
// demand rather than split statically, in blocks of consecutive tiles whose size shrinks
// as the work runs out (guided self-scheduling, a block being remaining / (2 ranks)):
// the pool answers O(P log(N/P)) requests for N tiles on P ranks, not N, and the
// last blocks are single tiles so the ranks finish together. Results never depend on the
// schedule: every tile is computed the same way wherever it runs.
//
// Who serves whom:
// - every rank that computes keeps its next block queued: it asks for one when it starts
//   the block before, so it never waits on a round trip;
// - rank 0 hands out blocks. Below `dedicated_root_ranks` ranks it computes too and
//   answers between blocks of points (the Serve callback); from there on it only
//   schedules;
// - across nodes, rank 0 hands big blocks to one leader per node, which sub-divides them
//   among its node's ranks and forwards their reports, so no process serves more than its
//   node's requests plus one message per leader (see docs/running.md, "Running on a
//   cluster");
// - at the end, ranks holding unstarted tiles give them back for the ranks out of work:
//   within a node through its leader, across nodes through rank 0; once nobody holds two,
//   a rank in the middle of a tile gives up its next one.
// Who writes compressed tiles (Writers, ScheduleSettings::writers): rank 0 alone, or rank 0
// and node leaders. A rank's flushed tiles travel with its reports up the tree to the first
// writer on the way (its node's leader when that leader writes; a leader that does not
// passes its node's aside to the leader that writes for it, or up to rank 0); a writer
// other than rank 0 writes them into file space rank 0 grants it (one round trip, asked
// ahead) and sends rank 0, in their place, where they lie.
// Resume: `pending` is what is left to do (job/tiles.hpp, handout_order: interleaved from
// 64 ranks on, so that a block's cost follows its size); a tile counts as done once rank 0
// has recorded its report (TilesDone, Writers::placed), which comes only after its data were
// handed over (TileWork::flush) and, with several writers, written. A rank lost mid-run
// loses at most the tiles not yet recorded: the next run's `pending` holds them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "io/stored_tiles.hpp"
#include "job/tiles.hpp"

namespace superball {

// Called from inside a rank's work every `points` points counted: a rank that serves
// others answers them (blocks, tiles back), a served rank its server's requests for tiles
// back. Empty on a rank alone (nobody to answer).
struct Serve {
    std::function<void()> call;
    // Points counted between two calls. A rank serving many ranks answers more often: at
    // 4096 simulated ranks, node leaders answering every 512 points (up to 0.1 s on the
    // costliest tiles) left every rank waiting 3.2 s on average, every 64 points 0.7 s
    // (tests/scale); smaller blocks cost the server a little of its own counting speed.
    std::size_t points = 512;

    explicit operator bool() const { return static_cast<bool>(call); }
    void operator()() const { call(); }
};

// What a rank hands over when it flushes: the reports of the tiles it finished since the
// last flush, in the order it computed them, and, when their data travel with the reports
// to rank 0 (compressed tiles, for rank 0's writer), those data.
struct Flushed {
    std::vector<TileReport> reports;
    std::vector<std::byte> payload;
};

// What a rank does with the tiles it is given.
class TileWork {
public:
    virtual ~TileWork() = default;
    // Counts tile `tile` and hands its data on (to the rank's writer, or to be sent).
    virtual void compute(std::uint64_t tile, const Serve& serve) = 0;
    // Hands over every tile computed so far and not yet handed over: either written to the
    // file (then only a tile reported here may be recorded done), or in the payload for
    // rank 0, which records them once it has written them.
    virtual Flushed flush() = 0;
    // True when what the rank holds should leave now, before the report period is over
    // (a bound on its memory).
    virtual bool should_flush() const { return false; }
};

// Called on rank 0 for finished tiles (see TileWork::flush) that reach it unwritten: the
// uncompressed ones (their rank wrote them) and the compressed ones rank 0 writes (with
// their payload), with the rank that computed them.
using TilesDone = std::function<void(std::span<const TileReport> tiles, int rank, std::span<const std::byte> payload)>;

// A writer of compressed tiles other than rank 0 (a node leader, ScheduleSettings::writers):
// takes the tiles of the ranks it writes for with their payloads (TileWork::flush), writes
// them into the file space rank 0 grants it, and gives them back placed once written. The
// pool polls it (never waits on it): its writes go on in the background.
class TileSink {
public:
    virtual ~TileSink() = default;
    virtual void add(std::span<const TileReport> tiles, std::span<const std::byte> payload) = 0;
    // Bytes of file space it needs beyond what it was granted (0: none).
    virtual std::uint64_t wanted() const = 0;
    virtual void grant(std::uint64_t address, std::uint64_t bytes) = 0;
    // The tiles written since the last call, where they lie; starts a write of what waits
    // when none is in flight.
    virtual std::vector<AppendedTile> written() = 0;
    // Some tile added has not been returned by written() yet.
    virtual bool holding() const = 0;
    // It holds more tiles waiting for file space than it would write at once: the pool takes
    // no more until rank 0's answer comes (its node's ranks then wait to send, as they would
    // for a writer that is busy), so that a burst of reports cannot grow it without bound.
    virtual bool full() const = 0;
};

// File space for a writer that asked for `bytes`: its address and size (rounded up to the
// file system's stripes).
struct FileSpace {
    std::uint64_t address = 0;
    std::uint64_t bytes = 0;
};

// The writers of compressed tiles beside rank 0. Empty (the default): rank 0 writes every
// tile (TilesDone), whatever ScheduleSettings::writers says.
struct Writers {
    // On every rank but 0: what this rank writes with if the pool makes it a writer.
    TileSink* sink = nullptr;
    // Rank 0: tiles another writer wrote, where they lie.
    std::function<void(std::span<const AppendedTile> tiles)> placed;
    // Rank 0: file space for a writer that asks (none overlaps another, nor rank 0's own).
    std::function<FileSpace(std::uint64_t bytes)> grant;
};
// Polled on every rank between tiles: true on any rank stops the run. Every rank then
// finishes the tile it is computing, drops the rest of its blocks, writes and reports
// what it computed, and returns (the run is interrupted).
using StopRequested = std::function<bool()>;

struct ScheduleSettings {
    // A rank with finished tiles flushes them and reports them at least this often, so
    // that the resume journal lags the work by little (node leaders pass reports on
    // every report_seconds / 2).
    double report_seconds = 1.0;
    // Blocks are multiples of this many tiles where they can be (a stripe of the file
    // system's alignment, so that two ranks' writes do not share one).
    std::uint64_t granule = 1;
    // A block is what is left over (block_divisor x ranks), per rank it serves (guided
    // self-scheduling; at least one tile).
    std::uint64_t block_divisor = 2;
    // Points counted between two looks for messages on a rank that serves at least
    // `busy_server_ranks` ranks (Serve::points; 512 elsewhere).
    std::size_t server_points = 64;
    int busy_server_ranks = 4;
    // With at least this many ranks, rank 0 computes no tile and only schedules (0:
    // never). Below it, a computing rank 0 loses little: it answers within a few hundred
    // points and its share of the work is 1/P; from about 64 ranks on its answers are
    // late often enough, and its share small enough, that one rank is better spent
    // scheduling.
    int dedicated_root_ranks = 64;
    // 0: nodes are the ranks sharing memory (MPI_Comm_split_type). n > 0: pseudo-nodes of
    // n consecutive ranks, which forces the two-level scheme on one machine (tests), or
    // names the nodes where MPI_Comm_split_type cannot (SMPI).
    int node_ranks = 0;
    // A server with nothing to do (a dedicated rank 0, a leader whose ranks are busy)
    // sleeps between looks for messages, longer and longer up to this: the delay of its
    // first answer after a quiet spell, and of its noticing a stop signal. (Idle, it
    // costs nothing either way; a simulation of hours of cluster time wants fewer looks.)
    double idle_poll_seconds = 1e-3;
    // Writers of compressed tiles (with Writers given): rank 0 and up to this many - 1 node
    // leaders, spread evenly over the nodes (each writes for the nodes from its own to the
    // next writer's); at most one per node, and 1 when the ranks form one node. 0 (auto): one
    // per node from `auto_writers_ranks` ranks on, else 1.
    int writers = 1;
    int auto_writers_ranks = 64;
};

// What one rank saw of the schedule (for tests, benchmarks and the simulation).
struct ScheduleStats {
    std::uint64_t tiles = 0;         // tiles this rank computed
    std::uint64_t blocks = 0;        // blocks it computed
    std::uint64_t flushes = 0;       // TileWork::flush calls that returned tiles
    std::uint64_t messages_in = 0;   // messages it received from the ranks it serves
    std::uint64_t requests_in = 0;   // of which requests for a block
    std::uint64_t messages_out = 0;  // messages it sent to the rank that serves it
    std::uint64_t payload_bytes_out = 0;  // bytes of its own tiles' payloads it sent
    // Sizes of the blocks a server (rank 0, node leaders) took from its pool, for the
    // ranks it serves and for itself, in order.
    std::vector<std::uint64_t> handed_out;
    std::uint64_t given_back = 0;    // tiles it gave back (to its server, or to its own pool)
    std::uint64_t asked_back = 0;    // requests for tiles back it sent to the ranks it serves
    double idle_seconds = 0;         // time it waited with nothing to compute (or to serve)
    bool two_level = false;          // node leaders were used (same on every rank)
    int writers = 1;                 // ranks that wrote compressed tiles (same on every rank)
    bool writer = false;             // this rank was one of them
    std::uint64_t tiles_placed = 0;  // tiles it wrote as a writer other than rank 0
    std::uint64_t grants = 0;        // file space it asked rank 0 for (rank 0: granted), times
    double space_wait_seconds = 0;   // a writer's time waiting for file space with a full sink
    bool leader = false;             // this rank served a node (rank 0 included)
    bool computed = false;           // this rank computed tiles (false: a scheduler only)
};

// Where a rank sits in the tree of servers (run_schedule finds it with MPI; tests make it
// up). With one level every rank is served by rank 0 and the "node" is the whole world.
struct PoolPlace {
    int rank = 0;            // in the world: rank 0 holds the pool
    int ranks = 1;           // in the world
    bool two_level = false;  // node leaders serve their nodes, rank 0 the leaders
    int node_rank = 0;       // in this rank's node (0: its leader)
    int node_size = 1;
    int leaders = 0;         // a node leader with two levels: the number of nodes
    int leader_rank = 0;     // a node leader: its rank among the leaders (rank 0: 0)
};

// A rank that this one serves: one of its node (Level::node), or, on rank 0 with two
// levels, a node leader (Level::leaders); `rank` is its rank at that level.
enum class Level { node = 0, leaders = 1 };
struct Peer {
    Level level = Level::node;
    int rank = 0;
};

// What the pool needs of the machine: messages up and down the tree, in the order sent
// between any two ranks, and a clock.
class PoolLinks {
public:
    virtual ~PoolLinks() = default;
    virtual double now() = 0;
    // Sleeps without holding the core another rank may need.
    virtual void pause(double seconds) = 0;
    // To the rank that serves this one.
    virtual void send_up(std::span<const std::uint64_t> words) = 0;
    virtual void send_down(Peer to, std::span<const std::uint64_t> words) = 0;
    // The next message that has arrived from a rank served at `level`: its rank there, and
    // the words in `words`; nothing when none has arrived.
    virtual std::optional<int> receive_up(Level level, std::vector<std::uint64_t>& words) = 0;
    // The next message from the server into `words` (its size): false when none has
    // arrived and `wait` is false; with `wait`, blocks until one does.
    virtual bool receive_down(std::span<std::uint64_t> words, bool wait) = 0;
    // Between node leaders (two levels): tiles on their way to the leader that writes them,
    // `leader` its rank among the leaders.
    virtual void send_aside(int leader, std::span<const std::uint64_t> words) = 0;
    // The next message that has arrived from another leader, if any.
    virtual bool receive_aside(std::vector<std::uint64_t>& words) = 0;
};

struct PoolResult {
    bool unfinished = false;  // rank 0: some pending tile was not recorded done
    ScheduleStats stats;      // this rank's
};

// One rank's part of the pool, until every rank is done. Every rank passes the same
// `pending` (the tiles to compute, in the order they are handed out; consecutive entries
// form the blocks) and settings.
PoolResult run_pool(PoolLinks& links, const PoolPlace& place, std::span<const ListedTile> pending, TileWork& work,
                    const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings,
                    const Writers& writers = {});

// The writers a run has (ScheduleSettings::writers resolved), the same on every rank.
int writer_count(const PoolPlace& place, const ScheduleSettings& settings);

}  // namespace superball
