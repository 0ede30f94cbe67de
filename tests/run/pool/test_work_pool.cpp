// The work pool (run/work_pool.hpp) in one process, on the fake machine of fake_machine.hpp
// (ranks as threads taking turns by their clocks, tile costs in simulated seconds): hand-out
// (every pending tile computed and recorded once, blocks that shrink, few requests, one level
// and node leaders), give-back when costs cluster, the tail (the last costly tiles split
// across ranks), resume (only pending tiles computed; stop, then resume, covers every tile
// once) and a lost machine (only tiles never recorded are computed again, and the record
// lags the work by at most a report period). Deterministic: the same on any load.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <vector>

#include "fake_machine.hpp"
#include "run/work_pool.hpp"

namespace superball {
namespace {

using testing::FakeMachine;

using testing::checksum_of;
using testing::listed_tiles;

using Cost = std::function<double(std::uint64_t tile)>;  // simulated seconds

// What the run did, as seen from outside the pool.
struct Record {
    explicit Record(int ranks)
        : computed(static_cast<std::size_t>(ranks)), ended(static_cast<std::size_t>(ranks)),
          written(static_cast<std::size_t>(ranks)), results(static_cast<std::size_t>(ranks)),
          finished_at(static_cast<std::size_t>(ranks), -1)
    {
    }
    std::vector<std::vector<std::uint64_t>> computed;  // per rank, in order
    std::vector<std::vector<double>> ended;            // per rank: the clock as each tile ended
    std::vector<std::set<std::uint64_t>> written;      // per rank: handed over by flush()
    std::map<std::uint64_t, int> recorded;             // rank 0's record: tile -> rank
    std::uint64_t recorded_twice = 0;
    std::uint64_t recorded_unwritten = 0;  // recorded before the rank that computed it wrote it
    std::uint64_t bad_payloads = 0;
    std::vector<PoolResult> results;
    std::vector<double> finished_at;  // the clock as each rank returned (-1: it did not)

    double makespan() const { return *std::max_element(finished_at.begin(), finished_at.end()); }
    std::uint64_t given_back() const
    {
        std::uint64_t n = 0;
        for (const PoolResult& r : results) n += r.stats.given_back;
        return n;
    }
};

// Stands for counting and writing: a tile of `points` points spends its cost on the rank's
// clock, calling `serve` as the counter does (every serve.points points); flush() writes the
// tiles computed since the last and hands their reports over with a payload naming them (an
// odd number of bytes, as compressed tiles travel with their reports).
class FakeWork final : public TileWork {
public:
    FakeWork(FakeMachine& m, int rank, Cost cost, Record& rec) : m_(m), rank_(rank), cost_(std::move(cost)), rec_(rec) {}

    void compute(std::uint64_t tile, const Serve& serve) override
    {
        // A tile that costs nothing takes no time and answers nobody (a region of launches that
        // miss the wall: microseconds a tile).
        const std::size_t slices = cost_(tile) == 0 ? 0 : serve ? (points + serve.points - 1) / serve.points : 1;
        for (std::size_t i = 0; i < slices; ++i) {
            m_.spend(rank_, cost_(tile) / static_cast<double>(slices));
            if (serve) serve();
        }
        rec_.computed[static_cast<std::size_t>(rank_)].push_back(tile);
        rec_.ended[static_cast<std::size_t>(rank_)].push_back(m_.clock(rank_));
        buffered_.push_back(tile);
    }

    Flushed flush() override
    {
        Flushed out;
        for (const std::uint64_t tile : buffered_) {
            out.reports.push_back({tile, checksum_of(tile)});
            rec_.written[static_cast<std::size_t>(rank_)].insert(tile);
        }
        out.payload.assign(8 * buffered_.size() + 3, std::byte{0x5a});
        std::memcpy(out.payload.data(), buffered_.data(), 8 * buffered_.size());
        buffered_.clear();
        return out;
    }

    static constexpr std::size_t points = 4096;

private:
    FakeMachine& m_;
    int rank_;
    Cost cost_;
    Record& rec_;
    std::vector<std::uint64_t> buffered_;
};

// The stop as a function of the rank and its clock (none by default).
using Stop = std::function<bool(int rank, double t)>;

// Runs the pool on every rank of `m`; what rank 0 records goes into the record, checked as
// it comes: once per tile, after the rank that computed it wrote it, with its payload.
Record run(FakeMachine& m, int ranks, std::span<const ListedTile> pending, const Cost& cost,
           const ScheduleSettings& settings, const Stop& stop = {})
{
    Record rec(ranks);
    m.run([&](int rank, PoolLinks& links) {
        FakeWork work(m, rank, cost, rec);
        const TilesDone done = [&rec](std::span<const TileReport> tiles, int from, std::span<const std::byte> payload) {
            if (payload.size() != 8 * tiles.size() + 3) ++rec.bad_payloads;
            for (std::size_t i = 0; i < tiles.size(); ++i) {
                const TileReport& t = tiles[i];
                std::uint64_t named = 0;
                if (payload.size() >= 8 * (i + 1)) std::memcpy(&named, payload.data() + 8 * i, 8);
                if (named != t.tile || t.checksum != checksum_of(t.tile)) ++rec.bad_payloads;
                if (!rec.written[static_cast<std::size_t>(from)].contains(t.tile)) ++rec.recorded_unwritten;
                if (!rec.recorded.emplace(t.tile, from).second) ++rec.recorded_twice;
            }
        };
        const StopRequested stopped = [&] { return stop && stop(rank, m.clock(rank)); };
        rec.results[static_cast<std::size_t>(rank)] = run_pool(links, m.place(rank), pending, work, done, stopped, settings);
        rec.finished_at[static_cast<std::size_t>(rank)] = m.clock(rank);
    });
    return rec;
}

void expect_every_tile_once(const Record& rec, std::span<const ListedTile> pending)
{
    std::multiset<std::uint64_t> computed;
    for (const auto& v : rec.computed) computed.insert(v.begin(), v.end());
    const std::multiset<std::uint64_t> expected(pending.begin(), pending.end());
    EXPECT_TRUE(computed == expected) << computed.size() << " tiles computed of " << expected.size();
    EXPECT_EQ(rec.recorded.size(), pending.size());
    EXPECT_EQ(rec.recorded_twice, 0u);
    EXPECT_EQ(rec.recorded_unwritten, 0u);
    EXPECT_EQ(rec.bad_payloads, 0u);
    EXPECT_FALSE(rec.results[0].unfinished);
}

TEST(HandOut, EveryTileOnceBlocksShrinkAndAreFew)
{
    const int ranks = 4;
    const std::uint64_t n = 2000;
    FakeMachine m({.ranks = ranks});
    const std::vector<ListedTile> pending = listed_tiles(n);
    const Record rec = run(m, ranks, pending, [](std::uint64_t) { return 1e-3; }, {});
    expect_every_tile_once(rec, pending);
    const std::vector<std::uint64_t>& blocks = rec.results[0].stats.handed_out;
    ASSERT_FALSE(blocks.empty());
    EXPECT_EQ(blocks.front(), n / (2 * ranks)) << "guided: what is left over twice the ranks";
    EXPECT_EQ(blocks.back(), 1u) << "the last blocks are single tiles";
    EXPECT_TRUE(std::is_sorted(blocks.rbegin(), blocks.rend())) << "a block grew (nothing was given back)";
    EXPECT_LE(rec.given_back(), static_cast<std::uint64_t>(ranks)) << "equal costs: at most a tile a rank at the end";
    const double bound = 2.0 * ranks * (std::log(static_cast<double>(n) / ranks) + 2);
    EXPECT_LE(static_cast<double>(blocks.size()), bound);
    EXPECT_LE(rec.results[0].stats.requests_in, blocks.size() + ranks) << "one request per block, one more per rank";
    // Equal costs: every rank computes its share, and they end together.
    const double ideal = static_cast<double>(n) * 1e-3 / ranks;
    EXPECT_LT(rec.makespan(), ideal * 1.02);
    for (int r = 0; r < ranks; ++r) EXPECT_TRUE(rec.results[static_cast<std::size_t>(r)].stats.computed);
}

TEST(HandOut, OneRankComputesEverythingWithoutAMessage)
{
    FakeMachine m({.ranks = 1});
    const std::vector<ListedTile> pending = listed_tiles(100);
    const Record rec = run(m, 1, pending, [](std::uint64_t) { return 1e-3; }, {});
    expect_every_tile_once(rec, pending);
    EXPECT_EQ(rec.results[0].stats.messages_in, 0u);
    EXPECT_EQ(rec.results[0].stats.messages_out, 0u);
}

// 32 ranks in nodes of 8, rank 0 only scheduling: rank 0 hears from the leaders only, a
// few messages per report period each, and every rank of every node computes.
TEST(HandOut, NodeLeadersServeTheirNodes)
{
    const int ranks = 32;
    FakeMachine m({.ranks = ranks, .node_ranks = 8});
    ScheduleSettings s;
    s.dedicated_root_ranks = 16;
    const std::vector<ListedTile> pending = listed_tiles(6000);
    const Record rec = run(m, ranks, pending, [](std::uint64_t t) { return 1e-4 * (1 + t % 7); }, s);
    expect_every_tile_once(rec, pending);
    EXPECT_FALSE(rec.results[0].stats.computed);
    EXPECT_TRUE(rec.results[0].stats.two_level);
    for (int r = 1; r < ranks; ++r) {
        EXPECT_FALSE(rec.computed[static_cast<std::size_t>(r)].empty()) << "rank " << r << " computed nothing";
        EXPECT_EQ(rec.results[static_cast<std::size_t>(r)].stats.leader, r % 8 == 0);
    }
    // Rank 0 serves 3 leaders (its own node's 7 ranks through itself as their leader).
    std::uint64_t leader_messages = 0;
    for (int r = 8; r < ranks; r += 8) leader_messages += rec.results[static_cast<std::size_t>(r)].stats.messages_out;
    EXPECT_LT(leader_messages, 6000u / 10) << "the leaders pass reports on in batches, not tile by tile";
    const double work = [&] {
        double w = 0;
        for (const std::uint64_t t : pending) w += 1e-4 * (1 + static_cast<double>(t % 7));
        return w;
    }();
    EXPECT_LT(rec.makespan(), 1.05 * work / (ranks - 1));
}

// The first eighth of the tiles costs 50 ms, the rest 1 ms: the first block (half a rank's
// share) holds every costly tile. The ranks that run out take back the unstarted tiles of
// the others (all but their next), so the run ends near the ideal instead of after the
// costly block.
TEST(GiveBack, CostlyTilesAreSharedWhenTheyCluster)
{
    const int ranks = 4;
    const std::uint64_t n = 400;
    FakeMachine m({.ranks = ranks});
    const Cost cost = [n](std::uint64_t t) { return 8 * t < n ? 50e-3 : 1e-3; };
    const std::vector<ListedTile> pending = listed_tiles(n);
    const Record rec = run(m, ranks, pending, cost, {});
    expect_every_tile_once(rec, pending);
    double work = 0;
    for (const std::uint64_t t : pending) work += cost(t);
    EXPECT_GT(rec.given_back(), 0u);
    // Without give-back: 2.5 s, the costly block on one rank.
    EXPECT_LT(rec.makespan(), work / ranks + 2 * 50e-3) << "ideal " << work / ranks;
}

// Across nodes: the costly tiles of one node's block go back through its leader and rank 0
// to the other nodes.
TEST(GiveBack, AcrossNodes)
{
    const int ranks = 16;
    const std::uint64_t n = 1600;
    FakeMachine m({.ranks = ranks, .node_ranks = 4});
    ScheduleSettings s;
    s.dedicated_root_ranks = 8;
    const Cost cost = [](std::uint64_t t) { return t < 150 ? 50e-3 : 1e-3; };
    const std::vector<ListedTile> pending = listed_tiles(n);
    const Record rec = run(m, ranks, pending, cost, s);
    expect_every_tile_once(rec, pending);
    double work = 0;
    for (const std::uint64_t t : pending) work += cost(t);
    std::set<int> nodes_with_costly;
    for (int r = 0; r < ranks; ++r) {
        for (const std::uint64_t t : rec.computed[static_cast<std::size_t>(r)]) {
            if (t < 150) nodes_with_costly.insert(r / 4);
        }
    }
    EXPECT_EQ(nodes_with_costly.size(), 4u) << "the costly tiles stayed on " << nodes_with_costly.size() << " nodes";
    EXPECT_LT(rec.makespan(), work / (ranks - 1) + 3 * 50e-3) << "ideal " << work / (ranks - 1);
}

// The tail: two tiles near the end cost 0.3 s, the rest nothing. A rank that starts one has
// asked ahead and may hold the other as its next; once the others are out of work it gives
// that one up from the middle of its tile (Down::give_one), so no rank computes both, one
// after the other. Every pair among the last eight tiles, since which rank holds which
// depends on the order of the requests.
TEST(Tail, TheLastCostlyTilesEndOnDifferentRanks)
{
    for (const auto& [ranks, dedicated] : {std::pair{3, false}, {4, true}, {5, true}}) {
        const std::uint64_t n = 20 * static_cast<std::uint64_t>(ranks);
        const std::vector<ListedTile> pending = listed_tiles(n);
        ScheduleSettings s;
        s.dedicated_root_ranks = dedicated ? 2 : 0;
        for (std::uint64_t i = n - 8; i < n; ++i) {
            for (std::uint64_t j = i + 1; j < n; ++j) {
                const auto costly = [i, j](std::uint64_t t) { return t == i || t == j; };
                FakeMachine m({.ranks = ranks});
                const Record rec = run(m, ranks, pending, [&](std::uint64_t t) { return costly(t) ? 0.3 : 0.0; }, s);
                expect_every_tile_once(rec, pending);
                for (int r = 0; r < ranks; ++r) {
                    const auto& mine = rec.computed[static_cast<std::size_t>(r)];
                    EXPECT_LE(std::count_if(mine.begin(), mine.end(), costly), 1)
                        << ranks << " ranks, tiles " << i << " and " << j << " costly: rank " << r << " computed both";
                }
                // A rank gives its next tile up between blocks of points (every 1/8 of a costly
                // tile here). A computing rank 0 also answers requests only then, so the others
                // may wait several such turns for their next tiles; a dedicated one at once.
                if (dedicated) {
                    EXPECT_LT(rec.makespan(), 0.3 + 0.3 / 8 + 0.01) << ranks << " ranks, tiles " << i << " and " << j << " costly";
                }
            }
        }
    }
}

// Resume: the tiles left to do are a scattered subset (the journal's gaps); only those are
// computed, each once.
TEST(Resume, OnlyThePendingTilesAreComputed)
{
    const int ranks = 3;
    std::vector<ListedTile> pending;
    for (std::uint64_t t = 0; t < 3000; ++t) {
        if (t % 3 == 1 || t % 7 == 0) pending.push_back(t);
    }
    FakeMachine m({.ranks = ranks});
    const Record rec = run(m, ranks, pending, [](std::uint64_t t) { return 1e-4 * (1 + t % 5); }, {});
    expect_every_tile_once(rec, pending);
}

// The run resumed after `first`: given the tiles of `all` it did not record, in their order,
// on a machine like its own, it records each of them once and none of `first`'s, so every
// tile is recorded once over the two runs.
void expect_resume_completes(const Record& first, std::span<const ListedTile> all, FakeMachine::Options machine,
                             const Cost& cost, const ScheduleSettings& settings)
{
    std::vector<ListedTile> rest;
    for (const ListedTile t : all) {
        if (!first.recorded.contains(t)) rest.push_back(t);
    }
    FakeMachine second(machine);
    const Record b = run(second, machine.ranks, rest, cost, settings);
    expect_every_tile_once(b, rest);
    for (const auto& [tile, rank] : b.recorded) EXPECT_FALSE(first.recorded.contains(tile)) << "tile " << tile;
    EXPECT_EQ(first.recorded.size() + b.recorded.size(), all.size()) << "node_ranks " << machine.node_ranks;
}

// A stop on one rank (a signal) ends every rank soon; the tiles recorded are a part of those
// computed, and a resumed run given the rest completes the grid: every tile recorded once
// over the two runs.
TEST(Resume, StopThenResumeRecordsEveryTileOnce)
{
    for (const int node_ranks : {0, 2}) {
        const int ranks = 6;
        const std::vector<ListedTile> all = listed_tiles(3000);
        const Cost cost = [](std::uint64_t t) { return 1e-3 * (1 + t % 3); };
        ScheduleSettings s;
        s.report_seconds = 0.05;
        FakeMachine first({.ranks = ranks, .node_ranks = node_ranks});
        const Record a = run(first, ranks, all, cost, s, [](int rank, double t) { return rank == ranks - 1 && t > 0.4; });
        EXPECT_TRUE(a.results[0].unfinished);
        EXPECT_GT(a.recorded.size(), 0u);
        EXPECT_EQ(a.recorded_twice, 0u);
        EXPECT_EQ(a.recorded_unwritten, 0u);
        // Every rank stops within a tile or two and a round trip of the signal.
        for (int r = 0; r < ranks; ++r) EXPECT_LT(a.finished_at[static_cast<std::size_t>(r)], 0.4 + 0.02) << "rank " << r;
        // Stopped cleanly: every tile computed was written and recorded.
        std::uint64_t computed = 0;
        for (const auto& v : a.computed) computed += v.size();
        EXPECT_EQ(computed, a.recorded.size());

        expect_resume_completes(a, all, {.ranks = ranks, .node_ranks = node_ranks}, cost, s);
    }
}

// A node lost mid-run takes the MPI job with it: every rank ends at once. What rank 0 had
// recorded stands (the journal); a tile is recorded only after its rank wrote it; the
// record lags the work by at most a report period and a tile; the requeued run, given what
// is not recorded, completes the grid with every tile recorded once in all.
TEST(LostRank, OnlyTilesNeverRecordedAreComputedAgain)
{
    for (const int node_ranks : {0, 4}) {
        const int ranks = 8;
        const std::vector<ListedTile> all = listed_tiles(4000);
        const Cost cost = [](std::uint64_t t) { return 1e-3 * (1 + t % 4); };
        ScheduleSettings s;
        s.report_seconds = 0.1;
        s.dedicated_root_ranks = 0;
        const double lost_at = 0.7;
        FakeMachine first({.ranks = ranks, .node_ranks = node_ranks});
        first.lose_all_at(lost_at);
        const Record a = run(first, ranks, all, cost, s);
        ASSERT_TRUE(first.lost());
        EXPECT_EQ(a.recorded_twice, 0u);
        EXPECT_EQ(a.recorded_unwritten, 0u) << "a tile recorded before its data were written";
        std::uint64_t computed = 0, late = 0;
        // Two levels: a leader passes reports on every half period.
        const double lag = s.report_seconds * (node_ranks > 0 ? 1.5 : 1.0) + 4e-3 + 1e-3;
        for (int r = 0; r < ranks; ++r) {
            const auto& tiles = a.computed[static_cast<std::size_t>(r)];
            const auto& ended = a.ended[static_cast<std::size_t>(r)];
            computed += tiles.size();
            for (std::size_t i = 0; i < tiles.size(); ++i) {
                if (ended[i] < lost_at - lag && !a.recorded.contains(tiles[i])) ++late;
            }
        }
        EXPECT_EQ(late, 0u) << "tiles computed long before the loss were not recorded (node_ranks " << node_ranks << ")";
        EXPECT_LT(a.recorded.size(), computed) << "nothing was in flight: the test lost nothing";
        EXPECT_GT(a.recorded.size(), 0u);

        expect_resume_completes(a, all, {.ranks = ranks, .node_ranks = node_ranks}, cost, s);
    }
}

// The fake machine itself: a run in which ranks wait for each other forever fails, rather
// than hanging (what a lost message in the pool would look like).
TEST(FakeMachineItself, AWaitThatNothingAnswersFails)
{
    FakeMachine m({.ranks = 2});
    EXPECT_THROW(m.run([](int rank, PoolLinks& links) {
        if (rank == 1) {
            std::vector<std::uint64_t> w(4);
            links.receive_down(w, true);
        }
    }),
                 std::runtime_error);
}

}  // namespace
}  // namespace superball
