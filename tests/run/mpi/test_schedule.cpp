// The schedule (run/schedule.hpp) under MPI, at whatever rank count the test runs with
// (ctest: 1 to 4): every pending tile computed and reported exactly once, only tiles the
// writer returned from a flush reported, and after they were written; blocks that shrink;
// a stop on one rank ending every rank promptly; reports that keep coming in the middle
// of long blocks; the same for rank 0 computing or only scheduling, one level or node
// leaders (forced on one machine by pseudo-nodes of two ranks).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <functional>
#include <cstring>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "mpi/mpi.hpp"
#include "run/schedule.hpp"
#include "shared_dir.hpp"

namespace superball {
namespace {

using test_support::world;

// One clock for every rank of this machine (CLOCK_MONOTONIC), unlike MPI_Wtime.
double seconds() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::uint64_t checksum_of(std::uint64_t tile) { return tile * 0x9E3779B97F4A7C15ull + 1; }

// Stands for counting and writing: a tile takes `tile_seconds` of sleep (so that
// oversubscribed ranks do not compete for the cores), calling `serve` four times; the
// "writer" keeps tiles until flush() writes them, and sends with their reports a payload
// naming them (an odd number of bytes: not a whole word), as compressed tiles travel.
class FakeWork final : public TileWork {
public:
    explicit FakeWork(double tile_seconds) : tile_seconds_(tile_seconds) {}

    void compute(std::uint64_t tile, const Serve& serve) override
    {
        started.push_back(seconds());
        for (int i = 0; i < 4; ++i) {
            if (tile_seconds_ > 0) std::this_thread::sleep_for(std::chrono::duration<double>(tile_seconds_ / 4));
            if (serve) serve();
        }
        computed.push_back(tile);
        ended.push_back(seconds());
        buffered_.push_back(tile);
    }

    Flushed flush() override
    {
        const double t = seconds();
        Flushed out;
        for (const std::uint64_t tile : buffered_) {
            out.reports.push_back({tile, checksum_of(tile)});
            written.push_back(tile);
            written_at.push_back(t);
        }
        out.payload = payload_of(out.reports);
        buffered_.clear();
        return out;
    }

    static std::vector<std::byte> payload_of(std::span<const TileReport> reports)
    {
        std::vector<std::byte> p(8 * reports.size() + 3, std::byte{0x5a});
        for (std::size_t i = 0; i < reports.size(); ++i) std::memcpy(p.data() + 8 * i, &reports[i].tile, 8);
        return p;
    }

    std::vector<std::uint64_t> computed;
    std::vector<double> started;
    std::vector<double> ended;
    std::vector<std::uint64_t> written;
    std::vector<double> written_at;

private:
    double tile_seconds_;
    std::vector<std::uint64_t> buffered_;
};

// Every rank's vector, on rank 0 (empty elsewhere).
std::vector<std::vector<std::uint64_t>> gather(const std::vector<std::uint64_t>& mine)
{
    const int n = static_cast<int>(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(world.size()));
    mpi::check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world.get()), "MPI_Gather");
    std::vector<int> offsets(counts.size());
    int total = 0;
    for (std::size_t r = 0; r < counts.size(); ++r) {
        offsets[r] = total;
        total += counts[r];
    }
    std::vector<std::uint64_t> all(static_cast<std::size_t>(world.is_root() ? total : 0));
    mpi::check(MPI_Gatherv(mine.data(), n, MPI_UINT64_T, all.data(), counts.data(), offsets.data(), MPI_UINT64_T, 0,
                           world.get()),
               "MPI_Gatherv");
    std::vector<std::vector<std::uint64_t>> out;
    if (world.is_root()) {
        for (std::size_t r = 0; r < counts.size(); ++r) {
            out.emplace_back(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
        }
    }
    return out;
}

std::vector<std::vector<double>> gather(const std::vector<double>& mine)
{
    std::vector<std::uint64_t> bits;
    for (const double x : mine) bits.push_back(std::bit_cast<std::uint64_t>(x));
    std::vector<std::vector<double>> out;
    for (const auto& v : gather(bits)) {
        out.emplace_back();
        for (const std::uint64_t b : v) out.back().push_back(std::bit_cast<double>(b));
    }
    return out;
}

struct Reported {
    TileReport report;
    int rank = 0;
    double at = 0;
};

// One run, and on rank 0 what every rank did.
struct Outcome {
    ScheduleResult result;  // this rank's
    double returned_at = 0;
    // Rank 0 only:
    std::vector<Reported> reported;
    std::uint64_t bad_payloads = 0;  // groups whose payload did not name their tiles
    std::vector<std::vector<std::uint64_t>> computed, written, handed_out;
    std::vector<std::vector<double>> started, ended, written_at, returned;
    std::vector<std::vector<std::uint64_t>> stats;  // per rank: tiles, blocks, flushes, computed (0/1), two_level, given_back
};

Outcome run_once(const std::vector<ListedTile>& pending, const ScheduleSettings& settings, double tile_seconds,
        const std::function<bool(const FakeWork&)>& stop_when = nullptr)
{
    FakeWork work(tile_seconds);
    Outcome out;
    const TilesDone done = [&](std::span<const TileReport> tiles, int rank, std::span<const std::byte> payload) {
        const double t = seconds();
        for (const TileReport& r : tiles) out.reported.push_back({r, rank, t});
        const std::vector<std::byte> sent = FakeWork::payload_of(tiles);
        if (!std::equal(sent.begin(), sent.end(), payload.begin(), payload.end())) ++out.bad_payloads;
    };
    const StopRequested stop = [&] { return stop_when && stop_when(work); };
    out.result = run_schedule(world, pending, work, done, stop, settings);
    out.returned_at = seconds();
    const ScheduleStats& s = out.result.stats;
    out.computed = gather(work.computed);
    out.written = gather(work.written);
    out.handed_out = gather(s.handed_out);
    out.started = gather(work.started);
    out.ended = gather(work.ended);
    out.written_at = gather(work.written_at);
    out.returned = gather(std::vector<double>{out.returned_at});
    out.stats = gather(std::vector<std::uint64_t>{s.tiles, s.blocks, s.flushes, s.computed ? 1u : 0u, s.two_level ? 1u : 0u,
                                                  s.given_back});
    return out;
}

// On rank 0: each reported tile was computed and written by the rank named, before it was
// reported, with its checksum and payload; no tile twice; every computed tile reported (all of them
// are written by the end, stopped or not); every pending tile when not interrupted.
void expect_reported_once(const Outcome& r, const std::vector<ListedTile>& pending)
{
    if (!world.is_root()) return;
    std::map<std::uint64_t, std::pair<int, double>> written;  // tile -> rank, time written
    std::set<std::uint64_t> computed;
    for (std::size_t rank = 0; rank < r.computed.size(); ++rank) {
        for (const std::uint64_t t : r.computed[rank]) EXPECT_TRUE(computed.insert(t).second) << "tile " << t << " computed twice";
        for (std::size_t i = 0; i < r.written[rank].size(); ++i) {
            written[r.written[rank][i]] = {static_cast<int>(rank), r.written_at[rank][i]};
        }
    }
    std::set<std::uint64_t> reported;
    for (const Reported& x : r.reported) {
        const std::uint64_t t = x.report.tile;
        EXPECT_TRUE(reported.insert(t).second) << "tile " << t << " reported twice";
        EXPECT_EQ(x.report.checksum, checksum_of(t)) << "tile " << t;
        const auto w = written.find(t);
        ASSERT_NE(w, written.end()) << "tile " << t << " reported but never written";
        EXPECT_EQ(w->second.first, x.rank) << "tile " << t << " reported for another rank than its writer";
        EXPECT_LE(w->second.second, x.at) << "tile " << t << " reported before it was written";
    }
    EXPECT_EQ(reported, computed) << "every computed tile is written and reported by the end";
    EXPECT_EQ(r.bad_payloads, 0u) << "payloads reach rank 0 whole, with the reports they came with";
    const std::set<std::uint64_t> all(pending.begin(), pending.end());
    for (const std::uint64_t t : computed) EXPECT_TRUE(all.count(t)) << "tile " << t << " was not pending";
    if (!r.result.interrupted) {
        EXPECT_EQ(reported, all);
    } else {
        EXPECT_LT(reported.size(), all.size());
    }
}

// Rank 0 computes or only schedules; one level, or node leaders over pseudo-nodes of two
// ranks (two levels from 3 ranks on); pseudo-nodes of one rank each are one level again.
struct Mode {
    const char* name;
    int dedicated_root_ranks;
    int node_ranks;
};

ScheduleSettings settings_of(const Mode& m)
{
    ScheduleSettings s;
    s.dedicated_root_ranks = m.dedicated_root_ranks;
    s.node_ranks = m.node_ranks;
    return s;
}

class Schedule : public testing::TestWithParam<Mode> {};

INSTANTIATE_TEST_SUITE_P(Modes, Schedule,
                         testing::Values(Mode{"one_level", 64, 0}, Mode{"dedicated_root", 2, 0},
                                         Mode{"two_level", 64, 2}, Mode{"two_level_dedicated_root", 2, 2},
                                         Mode{"one_rank_nodes", 64, 1}),
                         [](const testing::TestParamInfo<Mode>& i) { return std::string(i.param.name); });

// Tiles left after an interrupted run: gaps of every size.
std::vector<ListedTile> with_gaps(ListedTile tiles)
{
    std::vector<ListedTile> p;
    for (ListedTile t = 0; t < tiles; ++t) {
        if (t % 7 != 3 && !(t >= 1000 && t < 1100) && t != 1) p.push_back(t);
    }
    return p;
}

std::vector<ListedTile> iota(ListedTile n)
{
    std::vector<ListedTile> p(n);
    for (ListedTile t = 0; t < n; ++t) p[t] = t;
    return p;
}

TEST_P(Schedule, EveryPendingTileOnceWithGaps)
{
    const std::vector<ListedTile> pending = with_gaps(3000);
    const Outcome r = run_once(pending, settings_of(GetParam()), 0);
    EXPECT_FALSE(r.result.interrupted);
    const int ranks = world.size();
    EXPECT_EQ(r.result.stats.two_level, GetParam().node_ranks == 2 && ranks >= 3);
    EXPECT_EQ(r.result.stats.computed, !(world.is_root() && GetParam().dedicated_root_ranks == 2 && ranks >= 2));
    expect_reported_once(r, pending);
}

TEST_P(Schedule, BlocksAreWholeGranules)
{
    ScheduleSettings s = settings_of(GetParam());
    s.granule = 16;
    const std::vector<ListedTile> pending = iota(1000);
    // Tiles that take a moment (0.1 ms): a rank that starts late (a sanitizer, a loaded
    // machine) still finds fresh blocks in the pool rather than only tiles given back from
    // the middle of a granule, which the last check below would take for misaligned.
    const Outcome r = run_once(pending, s, 1e-4);
    expect_reported_once(r, pending);
    if (!world.is_root()) return;
    std::uint64_t aligned = 0;
    for (const auto& blocks : r.handed_out) {
        for (const std::uint64_t n : blocks) {
            if (n >= 16) {
                EXPECT_EQ(n % 16, 0u) << "a block of " << n << " tiles";
                ++aligned;
            }
        }
    }
    EXPECT_GT(aligned, 0u);
    // Each rank's computed tiles: a new run of consecutive tiles starts on a granule
    // while the blocks are granules (the first blocks: 1000 / (2 x 4 ranks) > 16).
    for (const auto& tiles : r.computed) {
        if (!tiles.empty()) {
            EXPECT_EQ(tiles.front() % 16, 0u);
        }
    }
}

TEST_P(Schedule, NothingPending)
{
    const Outcome r = run_once({}, settings_of(GetParam()), 0);
    EXPECT_FALSE(r.result.interrupted);
    EXPECT_EQ(r.result.stats.tiles, 0u);
    if (world.is_root()) {
        EXPECT_TRUE(r.reported.empty());
    }
}

TEST_P(Schedule, StopFromTheStartComputesNothing)
{
    const std::vector<ListedTile> pending = iota(100);
    const Outcome r = run_once(pending, settings_of(GetParam()), 0, [](const FakeWork&) { return true; });
    EXPECT_TRUE(r.result.interrupted);
    expect_reported_once(r, pending);
}

// The stop comes from rank 0 (Ctrl-C on it) or from the last rank (a worker; with node
// leaders, on another node than rank 0), 20 ms into a run of 2 ms tiles that would last
// about a second.
void stop_on_one_rank(const Mode& mode, int stopper)
{
    const double tile = 0.002;
    const std::vector<ListedTile> pending = iota(400 * static_cast<std::uint64_t>(world.size()));
    const double start = seconds();
    double stopped_at = 0;
    const Outcome r = run_once(pending, settings_of(mode), tile, [&](const FakeWork&) {
        if (world.rank() != stopper || seconds() < start + 0.02) return false;
        if (stopped_at == 0) stopped_at = seconds();
        return true;
    });
    EXPECT_TRUE(r.result.interrupted) << "on rank " << world.rank();
    expect_reported_once(r, pending);
    const auto stop_times = gather(std::vector<double>{stopped_at});
    if (!world.is_root()) return;
    const double stop_time = stop_times[static_cast<std::size_t>(stopper)].at(0);
    ASSERT_GT(stop_time, 0);
    for (std::size_t rank = 0; rank < r.started.size(); ++rank) {
        // An idle server looks for messages every millisecond (idle_poll_seconds): a
        // tile or two may start before the stop reaches a rank, none long after.
        const double last = r.started[rank].empty() ? 0 : *std::max_element(r.started[rank].begin(), r.started[rank].end());
        EXPECT_LT(last - stop_time, 0.05) << "rank " << rank << " started a tile long after the stop on rank " << stopper;
        EXPECT_LT(r.returned[rank][0] - stop_time, 0.25) << "rank " << rank << " returned late";
    }
}

TEST_P(Schedule, StopOnRankZeroEndsEveryRank) { stop_on_one_rank(GetParam(), 0); }

TEST_P(Schedule, StopOnTheLastRankEndsEveryRank)
{
    // A dedicated rank 0 computes nothing: with 1 or 2 ranks it is rank 0 or the only worker.
    stop_on_one_rank(GetParam(), world.size() - 1);
}

// The tests that take time run in two modes: the plain one, and the one with the most hops.
class ScheduleTimed : public Schedule {};

INSTANTIATE_TEST_SUITE_P(Modes, ScheduleTimed,
                         testing::Values(Mode{"one_level", 64, 0}, Mode{"two_level_dedicated_root", 2, 2},
                                         Mode{"one_rank_nodes", 64, 1}),
                         [](const testing::TestParamInfo<Mode>& i) { return std::string(i.param.name); });

// Blocks of 150 tiles of 1 ms, reports every 20 ms: the journal hears of each tile soon
// after it is computed, not when its block ends.
TEST_P(ScheduleTimed, ReportsArriveWithinThePeriodMidBlock)
{
    const double tile = 0.001;
    ScheduleSettings s = settings_of(GetParam());
    s.report_seconds = 0.02;
    const int ranks = world.size();
    const int computing = ranks - (GetParam().dedicated_root_ranks == 2 && ranks >= 2 ? 1 : 0);
    const std::vector<ListedTile> pending = iota(300 * static_cast<std::uint64_t>(computing));
    const Outcome r = run_once(pending, s, tile);
    expect_reported_once(r, pending);
    if (!world.is_root()) return;
    std::map<std::uint64_t, double> ended;
    for (std::size_t rank = 0; rank < r.computed.size(); ++rank) {
        for (std::size_t i = 0; i < r.computed[rank].size(); ++i) ended[r.computed[rank][i]] = r.ended[rank][i];
    }
    // A period, half one more through a node leader, and scheduling noise on 2 busy cores.
    const double bound = 1.5 * s.report_seconds + 0.08;
    double worst = 0;
    for (const Reported& x : r.reported) worst = std::max(worst, x.at - ended.at(x.report.tile));
    EXPECT_LT(worst, bound) << "a tile waited " << worst << " s to be reported; the first blocks last "
                            << 150 * tile << " s";
    // Without reports in the middle of blocks, the first tiles of the longest block
    // would wait for all of it.
    std::uint64_t longest = 0;
    for (const auto& blocks : r.handed_out) {
        for (const std::uint64_t b : blocks) longest = std::max(longest, b);
    }
    EXPECT_GT(static_cast<double>(longest) * tile, bound);
}

// Guided self-scheduling, one level: blocks of remaining / (2 ranks), never growing, down
// to single tiles; O(P log(N/P)) of them, not N. (Tiles given back at the end are handed
// out again after that.)
TEST(ScheduleOneLevel, BlocksShrinkAndAreFew)
{
    const std::uint64_t n = 20000;
    const std::vector<ListedTile> pending = iota(n);
    const Outcome r = run_once(pending, ScheduleSettings{}, 0);
    expect_reported_once(r, pending);
    if (!world.is_root()) return;
    const std::vector<std::uint64_t>& blocks = r.handed_out[0];
    const auto p = static_cast<std::uint64_t>(world.size());
    ASSERT_FALSE(blocks.empty());
    EXPECT_EQ(blocks.front(), n / (2 * p));
    const auto first_single = std::find(blocks.begin(), blocks.end(), 1u);
    EXPECT_NE(first_single, blocks.end()) << "the last blocks are single tiles";
    EXPECT_TRUE(std::is_sorted(std::make_reverse_iterator(first_single), blocks.rend())) << "a block grew";
    std::uint64_t sum = 0, given_back = 0;
    for (const std::uint64_t b : blocks) sum += b;
    for (const auto& st : r.stats) given_back += st[5];
    EXPECT_EQ(sum, n + given_back) << "every tile handed out once, and once more each time it was given back";
    const double bound = 2.0 * static_cast<double>(p) * (std::log(static_cast<double>(n) / static_cast<double>(p)) + 2);
    EXPECT_LE(static_cast<double>(blocks.size()), bound + static_cast<double>(given_back));
    EXPECT_LE(r.result.stats.requests_in, blocks.size() + p) << "one request per block, one more per rank";
}

// Tiles for which `costly` holds take `steps` sleeps of `step_ms`, answering messages
// between them; the others cost nothing and do not even call serve (with more ranks than
// cores, Open MPI yields the core in every probe, which would make them costly too).
class CostlyTiles final : public TileWork {
public:
    CostlyTiles(std::function<bool(std::uint64_t)> costly, int steps, int step_ms)
        : costly_(std::move(costly)), steps_(steps), step_ms_(step_ms)
    {
    }
    void compute(std::uint64_t tile, const Serve& serve) override
    {
        const bool costly = costly_(tile);
        for (int i = 0; costly && i < steps_; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(step_ms_));
            if (serve) serve();
        }
        if (costly) ++costly_tiles;
        done_.push_back({tile, checksum_of(tile)});
    }
    Flushed flush() override { return {std::exchange(done_, {}), {}}; }
    std::uint64_t costly_tiles = 0;

private:
    std::function<bool(std::uint64_t)> costly_;
    int steps_;
    int step_ms_;
    std::vector<TileReport> done_;
};

struct CostlyRun {
    ScheduleResult result;
    std::uint64_t most = 0;  // the most costly tiles one rank computed
};

// Tiles 0 to n - 1 in order, every one reported once, none interrupted.
CostlyRun run_costly(std::uint64_t n, CostlyTiles& work, const ScheduleSettings& settings)
{
    std::uint64_t reported = 0;
    const TilesDone done = [&](std::span<const TileReport> tiles, int, std::span<const std::byte>) { reported += tiles.size(); };
    CostlyRun r{run_schedule(world, iota(n), work, done, [] { return false; }, settings)};
    EXPECT_FALSE(r.result.interrupted);
    if (world.is_root()) {
        EXPECT_EQ(reported, n);
    }
    mpi::check(MPI_Allreduce(&work.costly_tiles, &r.most, 1, MPI_UINT64_T, MPI_MAX, world.get()), "MPI_Allreduce");
    return r;
}

int computing_ranks(const Mode& m)
{
    const int ranks = world.size();
    return ranks - (m.dedicated_root_ranks == 2 && ranks >= 2 ? 1 : 0);
}

// The first eighth of the tiles costs 32 ms, the rest nothing, so the first block (half a
// rank's share of tiles) holds all of the work: the ranks that run out of blocks take the
// unstarted tiles others hold (all but their next), and the costly tiles end up shared. (Counted, not
// timed: this machine's load makes times vary.)
TEST_P(ScheduleTimed, TilesGoBackWhenCostsCluster)
{
    const int computing = computing_ranks(GetParam());
    const std::uint64_t n = 100 * static_cast<std::uint64_t>(computing);
    CostlyTiles work([n](std::uint64_t tile) { return 8 * tile < n; }, 4, 8);
    const CostlyRun r = run_costly(n, work, settings_of(GetParam()));
    if (computing < 2) return;  // nobody to share with
    // The first block (half a rank's share, 50 tiles) holds every costly tile: without tiles
    // going back one rank would compute all of them. Shared fairly, each computes
    // heavy / computing; the bound leaves a margin for this machine's load (probes yield the
    // core to other ranks) and still fails if nothing goes back.
    const std::uint64_t heavy = n / 8 + (n % 8 != 0 ? 1 : 0);
    EXPECT_LE(r.most, heavy * 3 / 4) << "a rank computed " << r.most << " of the " << heavy
                                     << " costly tiles; it gave back " << r.result.stats.given_back;
}

// The last two tiles handed out are costly (0.3 s), the rest cost nothing: the rank that
// gets the first of them has asked ahead and may hold the second too. Once the others are
// out of work it gives that one up from the middle of its current tile (Down::give_one),
// so no rank computes both. (Counted, not timed.)
TEST_P(ScheduleTimed, TheLastCostlyTilesEndOnDifferentRanks)
{
    if (computing_ranks(GetParam()) < 2) GTEST_SKIP() << "one computing rank: nobody to give a tile to";
    const std::uint64_t n = 20 * static_cast<std::uint64_t>(computing_ranks(GetParam()));
    CostlyTiles work([n](std::uint64_t tile) { return tile + 2 >= n; }, 60, 5);
    EXPECT_EQ(run_costly(n, work, settings_of(GetParam())).most, 1u)
        << "one rank computed both costly tiles, one after the other";
}

}  // namespace
}  // namespace superball
