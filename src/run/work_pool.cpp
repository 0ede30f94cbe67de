#include "work_pool.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <deque>
#include <stdexcept>
#include <utility>

namespace superball {

namespace {

// Up message: {flags, weight, unstarted, received, idle, want, groups, the groups; ranges,
// then (first, count) per range}. The weight is the number of computing ranks the sender
// speaks for (1, or a node); unstarted, the most unstarted tiles one rank holds, of the
// sender and the ranks it serves (what asking it for tiles back can split; a node of many
// ranks with one tile each has nothing to give); received, the tiles its server has
// assigned it so far (so the server can add those still on their way); idle, how many of
// those ranks have nothing to compute; want, the bytes of file space a writer asks rank 0
// for (0: none); the ranges, tiles it gives back.
// A group: {rank, kind, n, n entries, ...}. Reported: entries (tile, checksum), then
// payload bytes b and the payload in ceil(b / 8) words. Placed (by a writer other than
// rank 0): entries (tile, checksum, address, counts bytes, outcomes bytes).
// Aside message (a leader to the leader that writes for it): {last, groups, the groups}.
constexpr std::uint64_t want_block = 1;     // asks for the next block
constexpr std::uint64_t final_message = 2;  // the sender is done: no message follows
constexpr std::uint64_t stopping = 4;       // the sender saw a stop: stop everyone
constexpr std::uint64_t gift = 8;           // answers give_back (with no range: none to give)
constexpr std::size_t up_header = 7;
enum class Group : std::uint64_t { reported = 0, placed = 1 };
constexpr std::uint64_t placed_words = 5;
// Down message: {kind, first, count, tiles the sender has left to hand out}.
// give_back: every unstarted tile but the next; give_one: the next too, from a rank in the
// middle of a tile (the end of a run, see PoolRank::rebalance); space: file space for a
// writer (first: its address, count: its bytes).
enum class Down : std::uint64_t { assign = 1, end = 2, stop = 3, bye = 4, give_back = 5, give_one = 6, space = 7 };
constexpr std::size_t down_words = 4;

// A group of an up or aside message, read in place.
struct GroupView {
    std::uint64_t rank = 0;
    Group kind = Group::reported;
    std::uint64_t n = 0;
    const std::uint64_t* entries = nullptr;
    std::span<const std::byte> payload;  // reported groups
    std::size_t words = 0;               // of the whole group

    static GroupView at(std::span<const std::uint64_t> msg, std::size_t i)
    {
        GroupView g;
        g.rank = msg[i];
        g.kind = static_cast<Group>(msg[i + 1]);
        g.n = msg[i + 2];
        g.entries = msg.data() + i + 3;
        if (g.kind == Group::placed) {
            g.words = 3 + placed_words * g.n;
            return g;
        }
        const std::uint64_t bytes = msg[i + 3 + 2 * g.n];
        g.payload = {reinterpret_cast<const std::byte*>(msg.data() + i + 4 + 2 * g.n), bytes};
        g.words = 4 + 2 * g.n + (bytes + 7) / 8;
        return g;
    }
    std::vector<TileReport> reports() const
    {
        std::vector<TileReport> r(n);
        for (std::uint64_t k = 0; k < n; ++k) r[k] = {entries[2 * k], entries[2 * k + 1]};
        return r;
    }
    std::vector<AppendedTile> placed() const
    {
        std::vector<AppendedTile> p(n);
        for (std::uint64_t k = 0; k < n; ++k) {
            const std::uint64_t* e = entries + placed_words * k;
            p[k] = {e[0], e[1], {e[2], e[3], e[4]}};
        }
        return p;
    }
};

// Writer w's place among L leaders when W write: the first leader of its share.
int first_of_share(int share, int leaders, int writers)
{
    return static_cast<int>((std::int64_t{share} * leaders + writers - 1) / writers);
}
int share_of(int leader, int leaders, int writers) { return static_cast<int>(std::int64_t{leader} * writers / leaders); }

struct TileRange {
    std::uint64_t first = 0;
    std::uint64_t count = 0;
};

// Guided self-scheduling: remaining / (divisor x ranks) entries per rank (at least one)
// for `weight` ranks; a multiple of the granule while that leaves at least one granule.
// A divisor above the classic 1 keeps every block a small part of a rank's share, so that
// a block of the costliest tiles (costs cluster in the grid) cannot outlast the others'
// work, and the last blocks are short enough that the ranks finish together.
std::uint64_t guided_block(std::uint64_t remaining, std::uint64_t ranks, std::uint64_t weight, std::uint64_t granule,
                           std::uint64_t divisor)
{
    std::uint64_t n = weight * std::max<std::uint64_t>(1, remaining / (divisor * std::max<std::uint64_t>(ranks, 1)));
    if (granule > 1 && n >= granule) n -= n % granule;
    return std::min(n, remaining);
}

// At most n tiles from the front of `r`, so that a block of a granule or more starts and
// ends on granule boundaries: a range given back from the middle of a granule (ranks give
// back tiles one by one, not granules) goes out first up to the next boundary.
std::uint64_t aligned_block(TileRange r, std::uint64_t n, std::uint64_t granule)
{
    if (granule <= 1 || n < granule) return n;
    const std::uint64_t into = r.first % granule;
    return into != 0 ? granule - into : n - n % granule;
}

// One rank's part of the schedule: a server (rank 0, node leaders) hands out blocks from
// its pool to the ranks it serves and passes their reports up; a rank with a server asks
// it for blocks; every rank but a dedicated rank 0 computes tiles from its pool.
//
// When a server's pool is empty for good (rank 0's, or a leader's once rank 0 has
// nothing more), the ranks that ask are not sent away while others still hold unstarted
// tiles: the server asks the rank holding the most (it learns that from every message)
// to give back all of them but the next (a leader so asked asks in turn every rank of its
// node holding two or more), and hands those out in guided blocks again. Costs cluster in
// the tile order (a block of the first, largest blocks can hold many times a rank's share
// of the work), so without this the run would last as long as its costliest block. All
// but one, not half: a rank whose block turned out costly held it whole until asked, and
// halving it took one round trip per halving while others waited (at 4096 simulated
// ranks, the ranks that kept their first block computed 76 s against a mean of 67, and
// the others waited 7 s each on average). Once nobody holds two, a rank in the middle of a
// tile is asked for its next one too (Down::give_one), one tile per rank out of work.
class PoolRank {
public:
    PoolRank(PoolLinks& links, const PoolPlace& place, std::span<const ListedTile> pending, TileWork& work,
              const TilesDone& done, const StopRequested& stop, const ScheduleSettings& s, const Writers& writers)
        : links_(links), pending_(pending), work_(work), done_(done), stop_(stop), settings_(s), writers_(writers)
    {
        const int ranks = place.ranks;
        world_rank_ = place.rank;
        root_ = world_rank_ == 0;
        leader_ = place.node_rank == 0;
        const bool dedicated = s.dedicated_root_ranks > 0 && ranks >= std::max(2, s.dedicated_root_ranks);
        computes_ = !(root_ && dedicated);
        computing_ranks_ = static_cast<std::uint64_t>(ranks - (dedicated ? 1 : 0));
        node_computing_ranks_ = static_cast<std::uint64_t>(place.node_size - (leader_ && !computes_ ? 1 : 0));
        stats.two_level = place.two_level;
        stats.leader = leader_;
        stats.computed = computes_;
        place_writers(place);

        if (root_) {
            if (!pending.empty()) pool_.push_back({0, pending.size()});
            pool_tiles_ = pending.size();
        }
        parent_remaining_ = pending.size();
        if (leader_) {
            by_node_rank_.assign(static_cast<std::size_t>(place.node_size), -1);
            for (int r = 1; r < place.node_size; ++r) add_child({Level::node, r}, by_node_rank_);
        }
        if (root_ && place.two_level) {
            by_leader_rank_.assign(static_cast<std::size_t>(place.leaders), -1);
            for (int r = 1; r < place.leaders; ++r) add_child({Level::leaders, r}, by_leader_rank_);
        }
        // Within a tile too: a server answers the ranks it serves, a served rank its
        // server's requests for tiles back.
        // A lone rank has no one to answer: its Serve stays empty, and the counter never
        // stops for it.
        if (!children_.empty() || !root_) serve_.call = [this] { poll_now_and_then(); };
        if (children_.size() >= static_cast<std::size_t>(std::max(1, s.busy_server_ranks))) serve_.points = s.server_points;
    }

    void run()
    {
        next_report_ = links_.now() + settings_.report_seconds;
        next_forward_ = links_.now() + settings_.report_seconds / 2;
        idle_ = computes_;  // nothing to compute yet
        maybe_request();
        for (;;) {
            if (!stopped_ && stop_()) begin_stop();
            if (computes_ && !stopped_ && next_tile()) {
                // Taken out of the block first: current_ holds unstarted tiles only, any of
                // which may be given back while this one is computed.
                const std::uint64_t i = current_.first++;
                --current_.count;
                computing_ = true;
                work_.compute(pending_[i], serve_);
                computing_ = false;
                ++stats.tiles;
                ++unflushed_;
                if (work_.should_flush()) report_own();
                after_tile();
                continue;
            }
            if (finished()) break;
            wait();
        }
        finish();
    }

    bool interrupted() const { return reported_ < pending_.size(); }

    ScheduleStats stats;

private:
    // Who writes what: a leader writes, passes its node's tiles aside to the leader that
    // writes for it, or passes them up (to rank 0, which writes for the first share).
    void place_writers(const PoolPlace& place)
    {
        const int count = writers_.sink || writers_.grant ? writer_count(place, settings_) : 1;
        stats.writers = count;
        stats.writer = root_;
        if (count <= 1 || !leader_ || root_) return;
        const int me = place.leader_rank;
        const int share = share_of(me, place.leaders, count);
        const int writer = first_of_share(share, place.leaders, count);
        if (writer != me) {
            if (writer != 0) aside_to_ = writer;
            return;
        }
        sink_ = writers_.sink;
        stats.writer = true;
        const int next = share + 1 < count ? first_of_share(share + 1, place.leaders, count) : place.leaders;
        aside_sources_ = next - me - 1;
    }

    struct Child {
        Peer peer;
        std::uint64_t weight = 1;
        std::uint64_t unstarted = 0;  // most unstarted tiles one rank under it holds, as last heard
        std::uint64_t assigned = 0;   // tiles assigned to it so far
        std::uint64_t in_flight = 0;  // of which it had not received when it last wrote
        std::uint64_t idle = 0;       // ranks under it with nothing to compute, as last heard
        bool active = true;           // no final message yet
        bool stop_sent = false;
        bool waiting = false;         // asked for a block this server does not have yet
        bool asked_back = false;      // was asked to give tiles back, no answer yet
        bool asked_one = false;       // ... for one tile (Down::give_one)
        bool for_server = false;      // ... for this rank's server, which waits for the answer
    };

    void add_child(Peer peer, std::vector<int>& index)
    {
        index[static_cast<std::size_t>(peer.rank)] = static_cast<int>(children_.size());
        children_.push_back({peer});
    }

    // The next tile to compute is current_.first once this returns true.
    bool next_tile()
    {
        if (current_.count > 0) return true;
        if (pool_tiles_ == 0) return false;
        // A rank without ranks to serve computes whole blocks as it got them; a server
        // takes its own share like the ranks it serves.
        const bool server = root_ || !children_.empty();
        current_ = take(server ? block_for(1) : pool_.front().count);
        if (server) stats.handed_out.push_back(current_.count);
        ++stats.blocks;
        idle_ = false;
        maybe_request();  // keeps the next block coming while this one is computed
        return true;
    }

    void after_tile()
    {
        const double t = poll_now_and_then();
        if (unflushed_ > 0 && t >= next_report_) report_own();
        send_reports_if_due();
    }

    // poll(), between tiles and within them, at most every poll_interval: a probe that
    // finds nothing costs little on a core of its own, but with more ranks than cores Open
    // MPI yields the core in every such probe, and a probe after every tile of a cheap
    // region (microseconds each) made 4 ranks on 2 cores take 0.45 s where 2 took 0.27
    // (tests/scale/validate.sh). Returns the time.
    double poll_now_and_then()
    {
        const double t = links_.now();
        if (t - last_poll_ >= poll_interval) {
            last_poll_ = t;
            poll();
        }
        return t;
    }

    // Blocks of `weight` ranks' worth under guided self-scheduling over what is left in
    // all: rank 0 knows; a node leader estimates it from what rank 0 had left when it
    // last answered, and its own pool as a sample of every node's. (Guided over the
    // leader's pool alone would cut it into crumbs whenever it runs low before a refill.)
    std::uint64_t block_for(std::uint64_t weight) const
    {
        const std::uint64_t left =
            root_ ? pool_tiles_ : parent_remaining_ + pool_tiles_ * computing_ranks_ / node_computing_ranks_;
        const TileRange& front = pool_.front();
        const std::uint64_t n =
            std::min(front.count, guided_block(left, computing_ranks_, weight, settings_.granule, settings_.block_divisor));
        return aligned_block(front, n, settings_.granule);
    }

    TileRange take(std::uint64_t n)
    {
        TileRange& front = pool_.front();
        const TileRange r{front.first, n};
        front.first += n;
        front.count -= n;
        pool_tiles_ -= n;
        if (front.count == 0) pool_.pop_front();
        return r;
    }

    void add_to_pool(TileRange r)
    {
        if (r.count == 0) return;
        pool_.push_back(r);
        pool_tiles_ += r.count;
    }

    // Ranks with nothing to compute here: this one, and those waiting under it.
    std::uint64_t idle_ranks() const
    {
        std::uint64_t n = idle_ ? 1 : 0;
        for (const Child& c : children_) {
            if (c.active && c.waiting) n += c.idle;
        }
        return n;
    }

    // The most unstarted tiles one rank holds: this one, or one it serves as last heard
    // (with the tiles on their way to it). Not the sum: a server asked for tiles back while
    // its ranks hold one each could give none, and would be asked again and again.
    std::uint64_t unstarted() const
    {
        std::uint64_t n = current_.count + pool_tiles_;
        for (const Child& c : children_) {
            if (c.active) n = std::max(n, c.unstarted + c.in_flight);
        }
        return n;
    }

    // Some rank served here holds, or is about to receive, tiles it could give back.
    bool splittable_below() const
    {
        return std::any_of(children_.begin(), children_.end(),
                           [](const Child& c) { return c.active && c.unstarted + c.in_flight >= 2; });
    }

    // This rank's unstarted tiles but the next (the end of its queue, then the end of its
    // current block), taken away: at most two ranges.
    std::vector<TileRange> take_back_surplus()
    {
        const std::uint64_t n = surplus(current_.count + pool_tiles_);
        stats.given_back += n;
        return take_back(n);
    }

    // Of n unstarted tiles, those a rank gives back: all but the next. (Not in whole
    // granules: that could keep a granule of the costliest tiles, 128 at 4096-point tiles;
    // the ranges given back at the end of a run are written in smaller pieces instead.)
    static std::uint64_t surplus(std::uint64_t n) { return n > 1 ? n - 1 : 0; }

    std::vector<TileRange> take_back(std::uint64_t n)
    {
        std::vector<TileRange> out;
        while (n > 0 && !pool_.empty()) {
            TileRange& back = pool_.back();
            const std::uint64_t k = std::min(n, back.count);
            out.push_back({back.first + back.count - k, k});
            back.count -= k;
            pool_tiles_ -= k;
            n -= k;
            if (back.count == 0) pool_.pop_back();
        }
        if (n > 0) {
            out.push_back({current_.first + current_.count - n, n});
            current_.count -= n;
        }
        return out;
    }

    // Writes this rank's finished tiles and queues their reports (rank 0 records them).
    void report_own()
    {
        next_report_ = links_.now() + settings_.report_seconds;
        if (unflushed_ == 0 || !computes_) return;
        unflushed_ = 0;
        const Flushed f = work_.flush();
        if (f.reports.empty()) return;
        ++stats.flushes;
        if (root_) {
            record(f.reports, world_rank_, f.payload);
            return;
        }
        stats.payload_bytes_out += f.payload.size();
        if (sink_) {
            sink_->add(f.reports, f.payload);
            tend_sink();
            return;
        }
        std::vector<std::uint64_t>& box = aside_to_ >= 0 && !f.payload.empty() ? aside_ : outbox_;
        box.push_back(static_cast<std::uint64_t>(world_rank_));
        box.push_back(static_cast<std::uint64_t>(Group::reported));
        box.push_back(f.reports.size());
        for (const TileReport& r : f.reports) {
            box.push_back(r.tile);
            box.push_back(r.checksum);
        }
        box.push_back(f.payload.size());
        const std::size_t at = box.size();
        box.resize(at + (f.payload.size() + 7) / 8, 0);
        if (!f.payload.empty()) std::memcpy(box.data() + at, f.payload.data(), f.payload.size());
        ++(&box == &aside_ ? aside_groups_ : outbox_groups_);
    }

    // A group of reported tiles from a rank this one serves (or, aside, from another
    // leader): written here, passed aside, or passed up.
    void route(std::span<const std::uint64_t> msg, std::size_t at, const GroupView& g)
    {
        const auto words = msg.subspan(at, g.words);
        if (g.kind == Group::reported && !g.payload.empty() && sink_) {
            sink_->add(g.reports(), g.payload);
            tend_sink();
        } else if (g.kind == Group::reported && !g.payload.empty() && aside_to_ >= 0) {
            aside_.insert(aside_.end(), words.begin(), words.end());
            ++aside_groups_;
        } else {
            outbox_.insert(outbox_.end(), words.begin(), words.end());
            ++outbox_groups_;
        }
    }

    // A writer's sink: file space asked for ahead (one request at a time), and the tiles it
    // wrote passed up to rank 0 in place of their data.
    void tend_sink()
    {
        if (!sink_) return;
        if (!space_asked_) {
            if (const std::uint64_t w = sink_->wanted(); w > 0) {
                space_asked_ = true;
                want_ = w;
                ++stats.grants;
                send_up(0);
            }
        }
        wait_for_space();
        const std::vector<AppendedTile> placed = sink_->written();
        if (placed.empty()) return;
        outbox_.insert(outbox_.end(), {static_cast<std::uint64_t>(world_rank_), static_cast<std::uint64_t>(Group::placed),
                                       placed.size()});
        for (const AppendedTile& t : placed) {
            outbox_.insert(outbox_.end(),
                           {t.tile, t.checksum, t.stored.address, t.stored.counts_bytes, t.stored.outcomes_bytes});
        }
        ++outbox_groups_;
        stats.tiles_placed += placed.size();
    }

    // A full sink waits for the file space it asked for, handling only its server's messages
    // meanwhile (not the ranks' it serves: their tiles are what it has no room for).
    void wait_for_space()
    {
        if (waiting_for_space_ || !space_asked_ || !sink_->full()) return;
        waiting_for_space_ = true;
        const double since = links_.now();
        std::array<std::uint64_t, down_words> msg{};
        while (space_asked_ && sink_->full()) {
            links_.receive_down(msg, true);
            on_down(msg);
        }
        stats.space_wait_seconds += links_.now() - since;
        waiting_for_space_ = false;
    }

    void send_aside(bool last)
    {
        if (aside_to_ < 0 || (aside_groups_ == 0 && !last)) return;
        std::vector<std::uint64_t> msg{last ? 1u : 0u, aside_groups_};
        msg.insert(msg.end(), aside_.begin(), aside_.end());
        std::vector<std::uint64_t>().swap(aside_);
        aside_groups_ = 0;
        next_aside_ = links_.now() + settings_.report_seconds / 2;
        links_.send_aside(aside_to_, msg);
    }

    bool drain_aside()
    {
        bool any = false;
        std::vector<std::uint64_t> msg;
        while (links_.receive_aside(msg)) {
            any = true;
            if (!sink_) throw std::logic_error("schedule: tiles passed aside to a leader that does not write");
            std::size_t at = 2;
            for (std::uint64_t g = 0; g < msg[1]; ++g) {
                const GroupView v = GroupView::at(msg, at);
                route(msg, at, v);
                at += v.words;
            }
            if (msg[0] != 0) --aside_sources_;
        }
        return any;
    }

    // A rank that only computes sends its reports at once; a node leader gathers its
    // node's for half a report period, so rank 0 hears from each node at most twice a
    // period whatever the node's size.
    void send_reports_if_due()
    {
        if (aside_groups_ > 0 && (links_.now() >= next_aside_ || aside_.size() >= forward_words)) send_aside(false);
        if (outbox_groups_ == 0 || root_) return;
        // A leader also passes them on once they hold more than a few MiB of data (its node's
        // compressed tiles), so that its memory stays bounded.
        if (!children_.empty() && links_.now() < next_forward_ && outbox_.size() < forward_words) return;
        send_up(0);
    }

    void record(std::span<const TileReport> reports, int rank, std::span<const std::byte> payload)
    {
        reported_ += reports.size();
        done_(reports, rank, payload);
    }

    void send_up(std::uint64_t flags, const std::vector<TileRange>& given = {})
    {
        sent_idle_ = idle_ranks();
        std::vector<std::uint64_t> msg{flags, children_.empty() ? 1 : node_computing_ranks_, unstarted(), received_,
                                       sent_idle_, std::exchange(want_, 0), outbox_groups_};
        msg.insert(msg.end(), outbox_.begin(), outbox_.end());
        msg.push_back(given.size());
        for (const TileRange& r : given) msg.insert(msg.end(), {r.first, r.count});
        // Its memory too: a rank's batch of compressed tiles passes through it once a second or
        // at 4 MiB, and kept, that much would stay on every rank for the rest of the run.
        std::vector<std::uint64_t>().swap(outbox_);
        outbox_groups_ = 0;
        next_forward_ = links_.now() + settings_.report_seconds / 2;
        links_.send_up(msg);
        ++stats.messages_out;
    }

    void send_down(Child& c, Down kind, TileRange r = {})
    {
        const std::array<std::uint64_t, down_words> msg = {static_cast<std::uint64_t>(kind), r.first, r.count, pool_tiles_};
        links_.send_down(c.peer, msg);
    }

    // Asks for the next block once the pool runs low: a rank that only computes when it
    // starts its last block; a node leader when less than one block per rank of its node
    // is left (at the rate rank 0 last handed blocks out).
    void maybe_request()
    {
        if (root_ || outstanding_ || parent_end_ || stopped_) return;
        const std::uint64_t low = children_.empty()
                                      ? 1
                                      : node_computing_ranks_ * std::max<std::uint64_t>(1, parent_remaining_ / (settings_.block_divisor * computing_ranks_));
        if (pool_tiles_ >= low) return;
        outstanding_ = true;
        send_up(want_block);
    }

    // Handles every message already waiting; true if there was one.
    bool poll()
    {
        bool any = false;
        if (by_node_rank_.size() > 1) any |= drain_up(Level::node, by_node_rank_);
        if (!by_leader_rank_.empty()) any |= drain_up(Level::leaders, by_leader_rank_);
        if (!root_) {
            std::array<std::uint64_t, down_words> msg{};
            while (links_.receive_down(msg, false)) {
                on_down(msg);
                any = true;
            }
        }
        if (sink_) {
            any |= drain_aside();
            tend_sink();
        }
        send_reports_if_due();
        return any;
    }

    bool drain_up(Level level, const std::vector<int>& index)
    {
        bool any = false;
        std::vector<std::uint64_t> msg;
        while (const std::optional<int> from = links_.receive_up(level, msg)) {
            on_up(children_[static_cast<std::size_t>(index[static_cast<std::size_t>(*from)])], msg);
            any = true;
        }
        return any;
    }

    void on_up(Child& c, const std::vector<std::uint64_t>& msg)
    {
        ++stats.messages_in;
        const std::uint64_t flags = msg[0];
        c.weight = msg[1];
        c.unstarted = msg[2];
        c.in_flight = c.assigned - msg[3];
        c.idle = msg[4];
        const std::uint64_t want = msg[5];
        const std::uint64_t groups = msg[6];
        std::size_t at = up_header;
        for (std::uint64_t g = 0; g < groups; ++g) {
            const GroupView v = GroupView::at(msg, at);
            if (!root_) {
                route(msg, at, v);
            } else if (v.kind == Group::placed) {
                const std::vector<AppendedTile> placed = v.placed();
                reported_ += placed.size();
                writers_.placed(placed);
            } else {
                record(v.reports(), static_cast<int>(v.rank), v.payload);
            }
            at += v.words;
        }
        if (want > 0) {
            // File space for a writer, whatever else goes on (a stopped run still writes
            // what it counted).
            const FileSpace f = writers_.grant(want);
            ++stats.grants;
            send_down(c, Down::space, {f.address, f.bytes});
        }
        std::vector<TileRange> given(msg[at]);
        for (std::size_t i = 0; i < given.size(); ++i) given[i] = {msg[at + 1 + 2 * i], msg[at + 2 + 2 * i]};

        if (flags & final_message) c.active = false;  // nothing more to tell it but goodbye
        // A rank told to stop (SIGTERM reaches every rank under Slurm) stops them all.
        if (flags & stopping) begin_stop();
        // The answer to a request for tiles back; a rank that ended instead gave none.
        if ((flags & gift) || ((flags & final_message) && c.asked_back)) {
            c.asked_back = false;
            // Nothing to give, whatever it said before (it started those tiles since, or
            // they were on their way): not asked again before its next message says so,
            // or rank 0 and a leader would trade requests and empty answers. Asked for all
            // but one, it may still hold that one (for Down::give_one at the end).
            if (std::all_of(given.begin(), given.end(), [](const TileRange& r) { return r.count == 0; })) {
                c.unstarted = c.asked_one ? 0 : std::min<std::uint64_t>(c.unstarted, 1);
            }
            c.asked_one = false;
            received_back(c, given);
        }
        if (flags & want_block) {
            ++stats.requests_in;
            answer(c);
        }
        if (flags & final_message) send_down(c, Down::bye);
        rebalance();
    }

    void answer(Child& c)
    {
        c.waiting = false;
        if (stopped_) return;  // the stop message is, or will be, on its way instead
        if (pool_tiles_ > 0) {
            const TileRange r = take(block_for(c.weight));
            stats.handed_out.push_back(r.count);
            c.assigned += r.count;
            c.in_flight += r.count;
            send_down(c, Down::assign, r);
        } else {
            c.waiting = true;  // answered when tiles come: from this server's server, or given back
            maybe_request();
        }
    }

    // Tiles given back by rank c, which this one serves: passed up with the others once
    // every rank asked for this rank's server has answered, handed out here otherwise.
    void received_back(Child& c, const std::vector<TileRange>& given)
    {
        if (c.for_server) {
            c.for_server = false;
            gathered_.insert(gathered_.end(), given.begin(), given.end());
            if (--owed_answers_ == 0) pass_gathered_up();
            return;
        }
        for (const TileRange& r : given) add_to_pool(r);
        serve_waiting();
    }

    void pass_gathered_up()
    {
        owe_back_ = false;
        owed_answers_ = 0;
        send_up(gift, gathered_);
        gathered_.clear();
    }

    void on_down(std::span<const std::uint64_t, down_words> msg)
    {
        switch (static_cast<Down>(msg[0])) {
        case Down::assign:
            outstanding_ = false;
            parent_remaining_ = msg[3];
            received_ += msg[2];
            add_to_pool({msg[1], msg[2]});
            serve_waiting();
            break;
        case Down::end:
            outstanding_ = false;
            parent_end_ = true;
            serve_waiting();
            break;
        case Down::stop:
            stop_from_parent_ = true;
            begin_stop();
            break;
        case Down::give_back:
            give_back();
            break;
        case Down::give_one:
            give_one();
            break;
        case Down::space:
            if (!sink_) throw std::logic_error("schedule: file space for a rank that does not write");
            space_asked_ = false;
            sink_->grant(msg[1], msg[2]);
            tend_sink();
            break;
        case Down::bye:
            throw std::logic_error("schedule: goodbye from the server before this rank's final message");
        }
    }

    // The server wants tiles back: this rank's own but the next, and those of every rank it
    // serves that holds two or more, passed up when they have all answered. All at once:
    // a node whose ranks hold the costliest tiles gives back in one round trip, not one
    // rank's tiles per round trip (the simulation at 1024 ranks lost a fifth of the run
    // to that, tests/scale).
    void give_back()
    {
        if (stopped_) {
            send_up(gift);
            return;
        }
        gathered_ = take_back_surplus();
        for (Child& c : children_) {
            if (c.active && !c.asked_back && c.unstarted >= 2) {
                ask(c);
                c.for_server = true;
                ++owed_answers_;
            }
        }
        if (owed_answers_ == 0) {
            pass_gathered_up();
        } else {
            owe_back_ = true;
        }
        maybe_request();  // the queued block may have gone back
    }

    // The server wants one tile for a rank out of work, at the end of the run: this rank's
    // next one if it is in the middle of a tile (between tiles it is about to start it), or
    // one from a rank it serves.
    void give_one()
    {
        if (stopped_) {
            send_up(gift);
            return;
        }
        if (computing_ && current_.count + pool_tiles_ > 0) {
            ++stats.given_back;
            gathered_ = take_back(1);
            pass_gathered_up();
            maybe_request();
            return;
        }
        if (Child* c = child_holding_one()) {
            ask(*c, Down::give_one);
            c->for_server = true;
            owed_answers_ = 1;
            owe_back_ = true;
            return;
        }
        send_up(gift);
    }

    // A rank served here that holds, as last heard, an unstarted tile and was not asked for it.
    Child* child_holding_one()
    {
        for (Child& c : children_) {
            if (c.active && !c.asked_back && c.unstarted + c.in_flight >= 1) return &c;
        }
        return nullptr;
    }

    const Child* fullest_child() const
    {
        const Child* best = nullptr;
        for (const Child& c : children_) {
            if (c.active && !c.asked_back && c.unstarted >= 2 && (!best || c.unstarted > best->unstarted)) best = &c;
        }
        return best;
    }

    // Asks the rank with the most unstarted tiles for all of them but one; false if none
    // has two.
    bool ask_back()
    {
        const Child* best = fullest_child();
        if (!best) return false;
        ask(children_[static_cast<std::size_t>(best - children_.data())]);
        return true;
    }

    void ask(Child& c, Down kind = Down::give_back)
    {
        c.asked_back = true;
        c.asked_one = kind == Down::give_one;
        ++stats.asked_back;
        send_down(c, kind);
    }

    // This rank first if it has nothing to compute either, then the ranks out of work, then
    // those that asked ahead. (A node leader used to serve its ranks first and keep what was
    // left: at 4096 simulated ranks the leaders computed 13.5 s of a 72 s run and waited the
    // rest, every block that reached them handed on before they looked at their own queue.)
    void serve_waiting()
    {
        if (idle_ && !stopped_ && current_.count == 0) next_tile();
        for (const bool idle : {true, false}) {
            for (Child& c : children_) {
                if (c.waiting && c.active && (c.idle > 0) == idle && pool_tiles_ > 0) answer(c);
            }
        }
        rebalance();
    }

    // With the pool empty and ranks waiting (this one included), asks for tiles back, from
    // as many ranks as are waiting. A node leader does so among its node's ranks as soon as
    // its own pool is empty, while its request to rank 0 is on its way: a rank of the node
    // holding several tiles answers in one round trip within the node, not three across
    // the tree (at 4096 simulated ranks the ranks waited a fifth of the second half of the
    // run when only rank 0 took tiles back). When nobody holds two unstarted tiles any
    // more and no more blocks come from above, the waiting ranks are done.
    void rebalance()
    {
        if (stopped_ || pool_tiles_ > 0 || children_.empty()) return;
        const bool last_word = root_ || parent_end_;  // no block will come from above
        // Rank 0 takes tiles back across nodes: it hears how many ranks here have nothing to do.
        if (!last_word && outstanding_ && idle_ranks() > sent_idle_) send_up(0);
        // Asked for tiles back by the server: this node's ranks with several were asked for it.
        if (owe_back_) return;
        bool anyone = false;
        for (const Child& c : children_) anyone = anyone || (c.active && c.waiting);
        if (!anyone && !idle_) return;
        // Tiles back for the ranks out of work, not for those still computing the block
        // they asked ahead of.
        const std::uint64_t waiting = idle_ranks();
        std::uint64_t asked = 0;
        for (const Child& c : children_) {
            if (c.active && c.asked_back) ++asked;
        }
        // This rank's own block first if it is the fullest: no message needed.
        const Child* fullest = fullest_child();
        if (waiting > 0 && current_.count >= 2 && (!fullest || current_.count >= fullest->unstarted)) {
            const std::uint64_t n = surplus(current_.count);
            stats.given_back += n;
            for (const TileRange& r : take_back(n)) add_to_pool(r);
            serve_waiting();
            return;
        }
        while (asked < waiting && ask_back()) ++asked;
        // Once no block will come from above and nobody holds two, a rank in the middle of a
        // tile gives up the next one it keeps: else the last tiles of the run may be a
        // rank's current tile and then its next, both among the costliest (at 4096
        // simulated ranks, sweep_e_alpha's last tile ended 11 s after the first rank ran
        // out of work, two tiles of 5.75 s; tests/scale). This rank's own first: no message.
        if ((last_word || parent_remaining_ == 0) && asked == 0 && fullest_child() == nullptr) {
            if (computing_ && current_.count == 1 && waiting > 0) {
                ++stats.given_back;
                for (const TileRange& r : take_back(1)) add_to_pool(r);
                serve_waiting();
                return;
            }
            while (asked < waiting) {
                Child* c = child_holding_one();
                if (!c) break;
                ask(*c, Down::give_one);
                ++asked;
            }
        }
        // Someone can still give tiles back, or blocks can come from above: the waiting
        // ranks wait for them.
        if (!last_word || asked > 0 || splittable_below() || current_.count >= 2) return;
        for (Child& c : children_) {
            if (c.active && c.waiting) {
                c.waiting = false;
                send_down(c, Down::end);
            }
        }
    }

    // No new tile from here on, anywhere: the ranks this one serves are told, and so is
    // its server (a plain rank says so in its final message).
    void begin_stop()
    {
        if (stopped_) return;
        stopped_ = true;
        for (Child& c : children_) {
            if (c.active && !c.stop_sent) {
                c.stop_sent = true;
                send_down(c, Down::stop);
            }
        }
        if (owe_back_) {
            // Late answers join this rank's pool, which a stopped rank never computes.
            for (Child& c : children_) c.for_server = false;
            pass_gathered_up();
        }
        if (!root_ && !children_.empty() && !stop_from_parent_) send_up(stopping);
    }

    bool finished() const
    {
        const bool own_done = !computes_ || stopped_ || (current_.count == 0 && pool_tiles_ == 0 && (root_ || parent_end_));
        // A writer goes on until every tile it was given is written and passed up: its own,
        // its node's, and those of the leaders that pass theirs aside to it (each says when
        // it has no more).
        const bool written = !sink_ || (unflushed_ == 0 && aside_sources_ == 0 && !sink_->holding());
        return own_done && written && !owe_back_ &&
               std::none_of(children_.begin(), children_.end(), [](const Child& c) { return c.active; });
    }

    // Nothing to compute: wait for a message (a plain rank blocks on its server's answer;
    // a server polls, sleeping a little longer each time nothing comes, so that it sees a
    // stop signal and never holds a core for nothing).
    void wait()
    {
        idle_ = computes_ && !stopped_;
        const double since = links_.now();
        struct Clock {
            PoolLinks& links;
            double since;
            double& total;
            ~Clock() { total += links.now() - since; }
        } clock{links_, since, stats.idle_seconds};
        if (unflushed_ > 0) report_own();  // idle anyway: a good time to write
        send_reports_if_due();
        if (children_.empty() && !sink_) {
            if (!outstanding_) throw std::logic_error("schedule: waiting with no request in flight");
            // The request went out ahead, when this rank still had a block: now it has
            // nothing, which its server needs to know to take tiles back for it.
            if (idle_ && sent_idle_ == 0) send_up(0);
            std::array<std::uint64_t, down_words> msg{};
            links_.receive_down(msg, true);
            on_down(msg);
            return;
        }
        rebalance();
        // A writer without ranks of its own to serve polls (for its file space and writes)
        // rather than blocking: it still tells its server when it runs out of work.
        if (children_.empty() && idle_ && outstanding_ && sent_idle_ == 0) send_up(0);
        if (poll()) {
            idle_pause_ = min_pause;
            return;
        }
        if (!stopped_ && stop_()) begin_stop();
        links_.pause(idle_pause_);
        idle_pause_ = std::min(2 * idle_pause_, std::max(min_pause, settings_.idle_poll_seconds));
    }

    void finish()
    {
        report_own();
        if (root_) return;
        send_aside(true);
        send_up(final_message | (stopped_ && !stop_from_parent_ ? stopping : 0));
        std::array<std::uint64_t, down_words> msg{};
        for (;;) {
            links_.receive_down(msg, true);
            if (static_cast<Down>(msg[0]) == Down::bye) return;  // answers, stops, asks: all moot now
        }
    }

    // An idle server polls every 20 us at first, then less and less often down to
    // settings_.idle_poll_seconds.
    static constexpr double min_pause = 20e-6;
    // Answers wait at most this much longer than when every tile polled.
    static constexpr double poll_interval = 50e-6;
    // 8 MiB of reports and payloads (in words).
    static constexpr std::size_t forward_words = std::size_t{1} << 20;
    double last_poll_ = -1;

    PoolLinks& links_;
    std::span<const ListedTile> pending_;
    TileWork& work_;
    const TilesDone& done_;
    const StopRequested& stop_;
    const ScheduleSettings& settings_;
    const Writers& writers_;
    int world_rank_ = 0;
    bool root_ = false;
    bool leader_ = false;
    bool computes_ = true;
    bool computing_ = false;  // in the middle of a tile (messages are handled from within it)
    std::uint64_t computing_ranks_ = 1;       // ranks computing tiles, in all
    std::uint64_t node_computing_ranks_ = 1;  // of which on this node
    Serve serve_;

    std::vector<Child> children_;
    std::vector<int> by_node_rank_;    // node rank -> index in children_ (leaders)
    std::vector<int> by_leader_rank_;  // leaders rank -> index in children_ (rank 0, two levels)
    bool outstanding_ = false;  // a request is on its way to the server
    bool parent_end_ = false;   // the server has no more blocks
    bool owe_back_ = false;     // the server asked for tiles back; ranks served here were asked in turn
    std::uint64_t owed_answers_ = 0;  // of which have not answered
    std::vector<TileRange> gathered_;     // tiles for the server so far
    std::uint64_t parent_remaining_ = 0;
    std::uint64_t received_ = 0;  // tiles the server assigned this rank so far
    std::uint64_t sent_idle_ = 0;  // idle ranks counted in the last message up

    std::deque<TileRange> pool_;
    std::uint64_t pool_tiles_ = 0;
    TileRange current_;  // unstarted tiles of the block being computed
    std::uint64_t unflushed_ = 0;  // tiles computed since the last flush
    std::vector<std::uint64_t> outbox_;  // report groups to send up
    std::uint64_t outbox_groups_ = 0;
    double next_report_ = 0;
    double next_forward_ = 0;
    double idle_pause_ = min_pause;
    bool idle_ = false;  // a computing rank with nothing to compute, waiting

    bool stopped_ = false;
    bool stop_from_parent_ = false;
    std::uint64_t reported_ = 0;  // rank 0: tiles recorded done

    // Writing (place_writers): this rank's sink if it writes for others (rank 0 aside), the
    // leader it passes its node's tiles to if not (-1: up), the leaders passing theirs here.
    TileSink* sink_ = nullptr;
    int aside_to_ = -1;
    int aside_sources_ = 0;
    bool space_asked_ = false;        // a request for file space is on its way
    bool waiting_for_space_ = false;  // in wait_for_space()
    std::uint64_t want_ = 0;          // file space asked for in the next message up
    std::vector<std::uint64_t> aside_;  // groups for aside_to_
    std::uint64_t aside_groups_ = 0;
    double next_aside_ = 0;
};

}  // namespace

PoolResult run_pool(PoolLinks& links, const PoolPlace& place, std::span<const ListedTile> pending, TileWork& work,
                    const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings, const Writers& writers)
{
    PoolRank s(links, place, pending, work, done, stop, settings, writers);
    s.run();
    return {s.interrupted(), std::move(s.stats)};
}

int writer_count(const PoolPlace& place, const ScheduleSettings& settings)
{
    if (!place.two_level || place.leaders < 2) return 1;
    const int asked = settings.writers > 0 ? settings.writers : place.ranks >= settings.auto_writers_ranks ? place.leaders : 1;
    return std::clamp(asked, 1, place.leaders);
}

}  // namespace superball
