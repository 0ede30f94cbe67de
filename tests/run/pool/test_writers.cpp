// Many writers in the work pool (run/work_pool.hpp: Writers, TileSink), on the fake machine
// of fake_machine.hpp: node leaders chosen as writers take their share of the nodes' tiles
// (their own node's, and those other leaders pass aside), write them into file space rank 0
// grants them, and pass up where they lie; rank 0 writes the first share itself. Checked:
// every tile recorded once, only after the writer that took it wrote it, with the payload
// its rank made; as many writers as asked (at most one per node, auto one per node from a
// size on); grants never overlap and every tile lies in its writer's; a stop, then a resume,
// and a lost machine record every tile once over the two runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
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
// A tile's stored bytes: sizes that vary, as compressed tiles' do.
std::uint64_t bytes_of(std::uint64_t tile) { return 100 + tile % 37 * 10; }

// What every rank saw, checked by the tests.
struct WritersRecord {
    explicit WritersRecord(int ranks) : computed(static_cast<std::size_t>(ranks)), results(static_cast<std::size_t>(ranks)) {}
    std::vector<std::vector<std::uint64_t>> computed;  // per rank
    std::map<std::uint64_t, int> recorded;             // rank 0's record: tile -> the rank that wrote it
    std::map<std::uint64_t, int> written;              // tile -> the rank whose writes ended (0: rank 0's own share)
    std::map<int, std::vector<std::pair<std::uint64_t, std::uint64_t>>> grants;  // writer -> [address, end)
    std::uint64_t recorded_twice = 0, recorded_unwritten = 0, bad_payloads = 0, misplaced = 0;
    std::vector<PoolResult> results;

    std::set<int> writers() const
    {
        std::set<int> w;
        for (const auto& [tile, rank] : written) w.insert(rank);
        return w;
    }
    void record(std::uint64_t tile, int writer)
    {
        if (!written.contains(tile)) ++recorded_unwritten;
        if (!recorded.emplace(tile, writer).second) ++recorded_twice;
    }
};

// The payload a rank makes of its tiles: each tile's number, then 3 bytes (an odd size).
std::vector<std::byte> payload_of(std::span<const TileReport> tiles)
{
    std::vector<std::byte> p(8 * tiles.size() + 3, std::byte{0x5a});
    for (std::size_t i = 0; i < tiles.size(); ++i) std::memcpy(p.data() + 8 * i, &tiles[i].tile, 8);
    return p;
}

bool names_its_tiles(std::span<const TileReport> tiles, std::span<const std::byte> payload)
{
    const std::vector<std::byte> want = payload_of(tiles);
    return std::equal(want.begin(), want.end(), payload.begin(), payload.end()) &&
           std::all_of(tiles.begin(), tiles.end(), [](const TileReport& t) { return t.checksum == checksum_of(t.tile); });
}

class WritersWork final : public TileWork {
public:
    WritersWork(FakeMachine& m, int rank, WritersRecord& rec) : m_(m), rank_(rank), rec_(rec) {}
    void compute(std::uint64_t tile, const Serve& serve) override
    {
        for (int i = 0; i < 4; ++i) {
            m_.spend(rank_, 1e-3 * (1 + static_cast<double>(tile % 3)) / 4);
            if (serve) serve();
        }
        rec_.computed[static_cast<std::size_t>(rank_)].push_back(tile);
        buffered_.push_back({tile, checksum_of(tile)});
    }
    Flushed flush() override
    {
        Flushed out{std::move(buffered_), {}};
        buffered_.clear();
        out.payload = payload_of(out.reports);
        return out;
    }

private:
    FakeMachine& m_;
    int rank_;
    WritersRecord& rec_;
    std::vector<TileReport> buffered_;
};

// A writer's sink: tiles placed whole in the space granted (asking for 256 bytes ahead),
// each write taking 2 ms of the machine's clock from its placing.
class FakeSink final : public TileSink {
public:
    FakeSink(FakeMachine& m, int rank, WritersRecord& rec) : m_(m), rank_(rank), rec_(rec) {}
    void add(std::span<const TileReport> tiles, std::span<const std::byte> payload) override
    {
        if (!names_its_tiles(tiles, payload)) ++rec_.bad_payloads;
        for (const TileReport& t : tiles) waiting_.push_back(t);
        place();
    }
    std::uint64_t wanted() const override
    {
        std::uint64_t need = ahead;
        for (const TileReport& t : waiting_) need += bytes_of(t.tile);
        return need > held() ? need - held() : 0;
    }
    void grant(std::uint64_t address, std::uint64_t bytes) override
    {
        rec_.grants[rank_].push_back({address, address + bytes});
        space_.push_back({address, address + bytes});
        place();
    }
    std::vector<AppendedTile> written() override
    {
        std::vector<AppendedTile> out;
        while (!writing_.empty() && writing_.front().first <= m_.clock(rank_)) {
            out.push_back(writing_.front().second);
            rec_.written[out.back().tile] = rank_;
            writing_.erase(writing_.begin());
        }
        return out;
    }
    bool holding() const override { return !waiting_.empty() || !writing_.empty(); }
    // More than 20 tiles wait for space (the test's tiles are 100-460 bytes).
    bool full() const override { return waiting_.size() > 20; }

    static constexpr std::uint64_t ahead = 256;

private:
    std::uint64_t held() const
    {
        std::uint64_t h = 0;
        for (const auto& [at, end] : space_) h += end - at;
        return h;
    }
    void place()
    {
        while (!waiting_.empty()) {
            const std::uint64_t size = bytes_of(waiting_.front().tile);
            while (!space_.empty() && space_.front().second - space_.front().first < size) space_.erase(space_.begin());
            if (space_.empty()) return;
            auto& r = space_.front();
            const TileReport t = waiting_.front();
            writing_.push_back({m_.clock(rank_) + 2e-3, {t.tile, t.checksum, {r.first, size, 0}}});
            r.first += size;
            waiting_.erase(waiting_.begin());
        }
    }

    FakeMachine& m_;
    int rank_;
    WritersRecord& rec_;
    std::vector<TileReport> waiting_;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> space_;
    std::vector<std::pair<double, AppendedTile>> writing_;  // done at, tile
};

using Stop = std::function<bool(int rank, double t)>;

// Runs the pool on every rank of `m` with writers; rank 0 grants space in stripes of 512
// bytes and writes its own share as it comes.
WritersRecord run(FakeMachine& m, int ranks, std::span<const ListedTile> pending, const ScheduleSettings& settings,
           const Stop& stop = {})
{
    WritersRecord rec(ranks);
    std::uint64_t next_free = 4096;  // past the file's own objects
    m.run([&](int rank, PoolLinks& links) {
        WritersWork work(m, rank, rec);
        FakeSink sink(m, rank, rec);
        Writers writers;
        const TilesDone done = [&rec](std::span<const TileReport> tiles, int, std::span<const std::byte> payload) {
            if (!names_its_tiles(tiles, payload)) ++rec.bad_payloads;
            for (const TileReport& t : tiles) {
                rec.written[t.tile] = 0;
                rec.record(t.tile, 0);
            }
        };
        if (rank == 0) {
            writers.placed = [&rec](std::span<const AppendedTile> tiles) {
                for (const AppendedTile& t : tiles) {
                    const auto w = rec.written.find(t.tile);
                    const int writer = w == rec.written.end() ? -1 : w->second;
                    rec.record(t.tile, writer);
                    if (t.stored.counts_bytes != bytes_of(t.tile)) ++rec.misplaced;
                    const auto& g = rec.grants[writer];
                    if (std::none_of(g.begin(), g.end(), [&](const auto& r) {
                            return r.first <= t.stored.address && t.stored.end() <= r.second;
                        })) {
                        ++rec.misplaced;
                    }
                }
            };
            writers.grant = [&next_free](std::uint64_t bytes) {
                const FileSpace f{next_free, (bytes + 511) / 512 * 512};
                next_free += f.bytes;
                return f;
            };
        } else {
            writers.sink = &sink;
        }
        const StopRequested stopped = [&] { return stop && stop(rank, m.clock(rank)); };
        rec.results[static_cast<std::size_t>(rank)] = run_pool(links, m.place(rank), pending, work, done, stopped, settings, writers);
    });
    return rec;
}

void expect_recorded_once(const WritersRecord& rec, std::span<const ListedTile> pending)
{
    std::multiset<std::uint64_t> computed;
    for (const auto& v : rec.computed) computed.insert(v.begin(), v.end());
    EXPECT_TRUE(computed == std::multiset<std::uint64_t>(pending.begin(), pending.end()));
    EXPECT_EQ(rec.recorded.size(), pending.size());
    EXPECT_EQ(rec.recorded_twice, 0u);
    EXPECT_EQ(rec.recorded_unwritten, 0u) << "a tile recorded before its writer wrote it";
    EXPECT_EQ(rec.bad_payloads, 0u);
    EXPECT_EQ(rec.misplaced, 0u) << "a tile placed outside its writer's file space";
    EXPECT_FALSE(rec.results[0].unfinished);
}

void expect_disjoint_grants(const WritersRecord& rec)
{
    std::vector<std::pair<std::uint64_t, std::uint64_t>> all;
    for (const auto& [writer, g] : rec.grants) all.insert(all.end(), g.begin(), g.end());
    std::sort(all.begin(), all.end());
    for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LE(all[i - 1].second, all[i].first) << "two grants overlap";
}

// 32 ranks in 8 nodes of 4: every leader writes (8), or 3 writers for the 8 nodes (leaders
// 0, 3 and 6 write; 1 and 2 pass theirs up to rank 0, 4 and 5 aside to 3, 7 aside to 6), or
// one; auto makes one a node from its size on. Rank 0 only schedules and writes.
TEST(Writers, EveryTileWrittenOnceByAsManyWritersAsAsked)
{
    const int ranks = 32;
    const std::vector<ListedTile> pending = listed_tiles(3000);
    const std::vector<int> each{0, 4, 8, 12, 16, 20, 24, 28}, three{0, 0, 0, 12, 12, 12, 24, 24}, one(8, 0);
    // Asked, auto from, writers, the writer of each node.
    for (const auto& [asked, auto_from, expected, writer_of_node] :
         {std::tuple{8, 64, 8, each}, {3, 64, 3, three}, {1, 64, 1, one}, {20, 64, 8, each}, {0, 16, 8, each},
          {0, 64, 1, one}}) {
        const std::set<int> leaders(writer_of_node.begin(), writer_of_node.end());
        FakeMachine m({.ranks = ranks, .node_ranks = 4});
        ScheduleSettings s;
        s.dedicated_root_ranks = 16;
        s.writers = asked;
        s.auto_writers_ranks = auto_from;
        const WritersRecord rec = run(m, ranks, pending, s);
        expect_recorded_once(rec, pending);
        expect_disjoint_grants(rec);
        EXPECT_EQ(rec.writers(), leaders) << asked << " writers asked";
        // Each tile by the writer of its node's share: aside from leaders that do not write.
        std::uint64_t elsewhere = 0;
        for (int r = 0; r < ranks; ++r) {
            for (const std::uint64_t t : rec.computed[static_cast<std::size_t>(r)]) {
                elsewhere += rec.written.at(t) != writer_of_node[static_cast<std::size_t>(r / 4)];
            }
        }
        EXPECT_EQ(elsewhere, 0u) << asked << " writers asked: tiles written by another than their node's writer";
        for (const PoolResult& r : rec.results) EXPECT_EQ(r.stats.writers, expected) << asked << " writers asked";
        std::uint64_t placed = 0;
        for (int r = 0; r < ranks; ++r) {
            const ScheduleStats& st = rec.results[static_cast<std::size_t>(r)].stats;
            EXPECT_EQ(st.writer, leaders.contains(r)) << "rank " << r;
            placed += st.tiles_placed;
        }
        EXPECT_EQ(placed, static_cast<std::uint64_t>(std::count_if(rec.written.begin(), rec.written.end(),
                                                                    [](const auto& w) { return w.second != 0; })));
        if (expected > 1) {
            EXPECT_GT(rec.results[0].stats.grants, 0u);
            // A rank's second of tiles comes at once: a writer whose sink filled waited for its space.
            double waited = 0;
            for (const PoolResult& r : rec.results) waited += r.stats.space_wait_seconds;
            EXPECT_GT(waited, 0.0) << asked << " writers asked";
        }
    }
}

// One node, or one rank a node: rank 0 writes alone, whatever is asked.
TEST(Writers, OneNodeHasOneWriter)
{
    for (const int node_ranks : {0, 1}) {
        FakeMachine m({.ranks = 6, .node_ranks = node_ranks});
        ScheduleSettings s;
        s.writers = 4;
        const std::vector<ListedTile> pending = listed_tiles(500);
        const WritersRecord rec = run(m, 6, pending, s);
        expect_recorded_once(rec, pending);
        EXPECT_EQ(rec.writers(), std::set<int>{0});
        EXPECT_EQ(rec.results[0].stats.writers, 1);
    }
}

// A stop on one rank, then a resume of what was not recorded; and a machine lost mid-run,
// then the same: every tile recorded once over the two runs, never before it was written.
TEST(Writers, StopOrLossThenResumeRecordsEveryTileOnce)
{
    const int ranks = 12;
    const std::vector<ListedTile> all = listed_tiles(2000);
    ScheduleSettings s;
    s.report_seconds = 0.05;
    s.writers = 3;
    for (const bool lose : {false, true}) {
        FakeMachine first({.ranks = ranks, .node_ranks = 3});
        if (lose) first.lose_all_at(0.15);
        const WritersRecord a = run(first, ranks, all, s, [&](int rank, double t) { return !lose && rank == ranks - 1 && t > 0.15; });
        EXPECT_EQ(a.recorded_twice, 0u);
        EXPECT_EQ(a.recorded_unwritten, 0u);
        EXPECT_EQ(a.misplaced, 0u);
        EXPECT_GT(a.recorded.size(), 0u);
        EXPECT_LT(a.recorded.size(), all.size());
        if (!lose) {
            // Stopped cleanly: every tile computed was written and recorded.
            std::uint64_t computed = 0;
            for (const auto& v : a.computed) computed += v.size();
            EXPECT_EQ(computed, a.recorded.size());
        }
        std::vector<ListedTile> rest;
        for (const ListedTile t : all) {
            if (!a.recorded.contains(t)) rest.push_back(t);
        }
        FakeMachine second({.ranks = ranks, .node_ranks = 3});
        const WritersRecord b = run(second, ranks, rest, s);
        expect_recorded_once(b, rest);
        EXPECT_EQ(a.recorded.size() + b.recorded.size(), all.size()) << (lose ? "lost" : "stopped");
    }
}

}  // namespace
}  // namespace superball
