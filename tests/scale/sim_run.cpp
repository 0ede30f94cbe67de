// The real schedule (src/run/schedule.cpp, over src/mpi/mpi.cpp) under SimGrid's SMPI,
// with counting and writing replaced by cost models: a tile costs what scale_costs
// computed from a real result of the job (smpi_execute), and the writer's flushes, rank
// 0's resume journal and the closing compression pass cost what the platform's shared file
// system makes them: its disk's bandwidth, shared by every operation in flight, after the
// latency per operation the disk's property op_latency states (S4U disk I/O).
// Built with smpicxx and run with smpirun by tests/scale/simulate.sh; prints one line of
// key=value on rank 0.
//
//   smpirun -np P -platform P.xml -hostfile H sim_run COSTS.bin [--node-ranks 32]
//       [--report-seconds 1] [--granule 1] [--block-divisor 2] [--dedicated-root-ranks 64] [--idle-poll 1e-3]
//       [--flush-bytes 6291456] [--journal-seconds 10]
//       [--compress-mbps 100] [--compress-ratio 100] [--no-io] [--no-closing] [--serve-every 0.05] [--server-serve-every 0.005] [--trace] [--trace-bucket 1]
#include <fcntl.h>
#include <mpi.h>
#include <smpi/smpi.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <simgrid/s4u/Actor.hpp>
#include <simgrid/s4u/Comm.hpp>
#include <simgrid/s4u/Disk.hpp>
#include <simgrid/s4u/Engine.hpp>
#include <simgrid/s4u/Host.hpp>
#include <simgrid/s4u/Mailbox.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "mpi/mpi.hpp"
#include "run/schedule.hpp"

namespace {

using namespace superball;

// The cost file of scale_costs, mapped read-only: every simulated rank shares its pages.
class Costs {
public:
    explicit Costs(const std::string& path)
    {
        const int fd = ::open(path.c_str(), O_RDONLY);
        if (fd < 0) throw std::runtime_error("cannot open " + path);
        struct stat st {};
        ::fstat(fd, &st);
        size_ = static_cast<std::size_t>(st.st_size);
        data_ = ::mmap(nullptr, size_, PROT_READ, MAP_SHARED, fd, 0);
        ::close(fd);
        if (data_ == MAP_FAILED) throw std::runtime_error("cannot map " + path);
        const auto* bytes = static_cast<const char*>(data_);
        if (size_ < 32 || std::memcmp(bytes, "SBCOST01", 8) != 0) throw std::runtime_error(path + ": not a cost file");
        const auto* header = reinterpret_cast<const std::uint64_t*>(bytes + 8);
        tiles_ = header[0];
        bytes_per_point_ = header[1];
        points_ = header[2];
        if (size_ != 32 + tiles_ * 24) throw std::runtime_error(path + ": truncated");
        cost_ = reinterpret_cast<const double*>(bytes + 32);
        tile_points_ = reinterpret_cast<const std::uint64_t*>(bytes + 32 + 8 * tiles_);
        pending_ = reinterpret_cast<const std::uint64_t*>(bytes + 32 + 16 * tiles_);
    }
    ~Costs() { ::munmap(data_, size_); }
    Costs(const Costs&) = delete;
    Costs& operator=(const Costs&) = delete;

    std::uint64_t tiles() const { return tiles_; }
    std::uint64_t bytes_per_point() const { return bytes_per_point_; }
    std::uint64_t points() const { return points_; }
    double cost(std::uint64_t t) const { return cost_[t]; }
    std::uint64_t tile_points(std::uint64_t t) const { return tile_points_[t]; }
    std::span<const std::uint64_t> pending() const { return {pending_, tiles_}; }

private:
    void* data_ = nullptr;
    std::size_t size_ = 0;
    std::uint64_t tiles_ = 0, bytes_per_point_ = 0, points_ = 0;
    const double* cost_ = nullptr;
    const std::uint64_t* tile_points_ = nullptr;
    const std::uint64_t* pending_ = nullptr;
};

struct Options {
    std::string costs;
    ScheduleSettings schedule;
    double flush_bytes = 6 << 20;  // the writer's buffer: 4 MiB of 16-bit counts, 2 MiB of outcomes (run/explore.cpp)
    double journal_seconds = 10;
    double compress_mbps = 100;    // shuffle + deflate, per core
    double compress_ratio = 100;
    bool io = true;
    bool closing = true;           // false: no closing pass (schedule experiments)
    bool trace = false;            // one line per rank on standard error (where the tail comes from)
    double trace_bucket = 1;       // seconds: the waits between tiles summed over ranks by this
    double serve_every = 0.05;     // most compute seconds between two Serve calls (see ModelWork)
    // The same for ranks that serve many (Serve::points below 512: node leaders).
    double server_serve_every = 0.005;
};

Options parse(int argc, char** argv)
{
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&] {
            if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
            return std::string(argv[++i]);
        };
        if (a == "--node-ranks") o.schedule.node_ranks = std::stoi(value());
        else if (a == "--report-seconds") o.schedule.report_seconds = std::stod(value());
        else if (a == "--granule") o.schedule.granule = std::stoull(value());
        else if (a == "--block-divisor") o.schedule.block_divisor = std::stoull(value());
        else if (a == "--dedicated-root-ranks") o.schedule.dedicated_root_ranks = std::stoi(value());
        else if (a == "--idle-poll") o.schedule.idle_poll_seconds = std::stod(value());
        else if (a == "--flush-bytes") o.flush_bytes = std::stod(value());
        else if (a == "--journal-seconds") o.journal_seconds = std::stod(value());
        else if (a == "--compress-mbps") o.compress_mbps = std::stod(value());
        else if (a == "--compress-ratio") o.compress_ratio = std::stod(value());
        else if (a == "--no-io") o.io = false;
        else if (a == "--no-closing") o.closing = false;
        else if (a == "--trace") o.trace = true;
        else if (a == "--trace-bucket") o.trace_bucket = std::stod(value());
        else if (a == "--serve-every") o.serve_every = std::stod(value());
        else if (a == "--server-serve-every") o.server_serve_every = std::stod(value());
        else if (o.costs.empty() && a.rfind("--", 0) != 0) o.costs = a;
        else throw std::runtime_error("unknown argument " + a);
    }
    if (o.costs.empty()) throw std::runtime_error("usage: sim_run COSTS.bin [options]");
    return o;
}

// The shared file system: the disk of the platform's host "fs", which every rank's
// operations share (its bandwidth is the file system's aggregate), after the latency of an
// operation (its property op_latency, in seconds: an RPC and a lock on Lustre).
class FileSystem {
public:
    explicit FileSystem(const Options& o) : on_(o.io)
    {
        if (!on_) return;
        const auto disks = simgrid::s4u::Host::by_name("fs")->get_disks();
        if (disks.empty()) throw std::runtime_error("the platform's host fs has no disk");
        disk_ = disks.front();
        const char* latency = disk_->get_property("op_latency");
        if (!latency) throw std::runtime_error("the platform's disk of host fs states no op_latency");
        latency_ = std::stod(latency);
    }
    void write(double bytes) { io(bytes, true); }
    void read(double bytes) { io(bytes, false); }
    std::uint64_t operations = 0;

private:
    void io(double bytes, bool write)
    {
        if (!on_ || bytes <= 0) return;
        ++operations;
        simgrid::s4u::this_actor::sleep_for(latency_);
        const auto n = static_cast<sg_size_t>(std::ceil(bytes));
        if (write) disk_->write(n);
        else disk_->read(n);
    }

    double latency_ = 0;
    bool on_;
    simgrid::s4u::Disk* disk_ = nullptr;
};

// The writer thread of a rank (io/partial_file.cpp, TileWriter): one buffer fills while
// the other is written, so a rank waits for a write only when the next buffer is full
// before the last one reached the file system, and when it flushes (every report period,
// and when it is idle). Here an S4U actor on the rank's host, fed one job at a time.
class WriterThread {
public:
    WriterThread(FileSystem& fs, int rank)
        : fs_(fs),
          jobs_(simgrid::s4u::Mailbox::by_name("writer-jobs-" + std::to_string(rank))),
          acks_(simgrid::s4u::Mailbox::by_name("writer-acks-" + std::to_string(rank)))
    {
        simgrid::s4u::Actor::create("writer-" + std::to_string(rank), simgrid::s4u::this_actor::get_host(),
                                    [this] { loop(); })
            ->daemonize();
    }
    // The actor ends before this object: it runs on the rank's host until told.
    ~WriterThread()
    {
        wait();
        quit_ = true;
        jobs_->put(&job_, 0);
    }
    WriterThread(const WriterThread&) = delete;
    WriterThread& operator=(const WriterThread&) = delete;
    // Starts writing `ops` (bytes of each write call) once the write before has ended.
    void issue(const std::vector<double>& ops)
    {
        wait();
        job_ = ops;
        jobs_->put(&job_, 0);
        busy_ = true;
    }
    void wait()
    {
        if (!busy_) return;
        acks_->get<std::vector<double>>();
        busy_ = false;
    }

private:
    void loop()
    {
        for (;;) {
            // The mailboxes only signal: SMPI's copy of message data does not carry S4U
            // payloads, so the job is read from this object.
            jobs_->get<std::vector<double>>();
            if (quit_) return;
            for (const double bytes : job_) fs_.write(bytes);
            acks_->put(&job_, 0);
        }
    }

    FileSystem& fs_;
    simgrid::s4u::Mailbox* jobs_;
    simgrid::s4u::Mailbox* acks_;
    std::vector<double> job_;
    bool quit_ = false;
    bool busy_ = false;
};

// Counting replaced by smpi_execute of the tile's modelled cost, in pieces with the Serve
// callback between them. The real counter calls it every Serve::points points (512, 64
// on a node leader); so does the model where that many points cost more than
// --serve-every seconds (--server-serve-every on a leader: a rank holding heavy tiles
// answers as late as the real one), and every --serve-every seconds of compute elsewhere
// (fewer events: answers come later than in the real run by at most that, never sooner);
// writing as the writer does: tiles buffered until ~6 MiB, a tile that does not follow the
// last, or a flush, then one write to /wall_bounces and one to /outcome on the writer
// thread.
class ModelWork final : public TileWork {
public:
    ModelWork(const Costs& c, FileSystem& fs, const Options& o, int rank)
        : costs_(c),
          writer_(fs, rank),
          flush_bytes_(o.flush_bytes),
          serve_every_(o.serve_every),
          server_serve_every_(o.server_serve_every),
          io_(o.io)
    {
    }

    void compute(std::uint64_t tile, const Serve& serve) override
    {
        const double cost = costs_.cost(tile);
        const std::uint64_t points = costs_.tile_points(tile);
        // Time since the last tile (waiting, scheduling, writing), by second of the run.
        const double begin = MPI_Wtime();
        if (begin > last_end) {
            const auto second = static_cast<std::size_t>(std::max(0.0, last_end / bucket));
            if (second >= gaps.size()) gaps.resize(second + 1, 0.0);
            gaps[second] += begin - last_end;
        }
        // A tile that does not follow the buffered ones, or a full buffer, is written first.
        const double bytes = static_cast<double>(points * costs_.bytes_per_point());
        if (buffered_points_ > 0 && (tile != next_tile_ || buffered_bytes_ + bytes > flush_bytes_)) issue();
        // A rank serving many calls Serve more often (schedule.hpp, Serve::points).
        const double every = serve.points < 512 ? server_serve_every_ : serve_every_;
        const auto wanted = static_cast<std::uint64_t>(std::ceil(cost / every));
        const std::uint64_t most = std::max<std::uint64_t>(1, points / std::max<std::size_t>(1, serve.points));
        const int pieces = static_cast<int>(std::clamp<std::uint64_t>(wanted, 1, most));
        for (int i = 0; i < pieces; ++i) {
            smpi_execute(cost / pieces);
            if (serve) serve();
        }
        busy += cost;
        ++tiles;
        last_end = MPI_Wtime();
        next_tile_ = tile + 1;
        buffered_points_ += points;
        buffered_.push_back(tile);
        buffered_bytes_ += bytes;
    }

    std::vector<TileReport> flush() override
    {
        issue();
        writer_.wait();
        std::vector<TileReport> out;
        for (const std::uint64_t t : written_) out.push_back({t, t});
        written_.clear();
        return out;
    }

    double busy = 0;
    std::uint64_t tiles = 0;
    double last_end = 0;       // set to the start of the run before the first tile
    double bucket = 1;         // of the gaps, in seconds
    std::vector<double> gaps;  // seconds between tiles (and before the first), by bucket of the run their wait began

private:
    void issue()
    {
        if (buffered_points_ == 0) return;
        const double count_bytes = static_cast<double>(costs_.bytes_per_point() - 1);
        const double p = static_cast<double>(buffered_points_);
        if (io_) writer_.issue({p * count_bytes, p});
        written_.insert(written_.end(), buffered_.begin(), buffered_.end());
        buffered_.clear();
        buffered_points_ = 0;
        buffered_bytes_ = 0;
    }

    const Costs& costs_;
    WriterThread writer_;
    double flush_bytes_;
    double serve_every_;
    double server_serve_every_;
    bool io_;
    std::uint64_t next_tile_ = 0;
    std::uint64_t buffered_points_ = 0;
    std::vector<std::uint64_t> buffered_;
    std::vector<std::uint64_t> written_;  // issued; reported at the next flush, once written
    double buffered_bytes_ = 0;
};

int run(int argc, char** argv)
{
    const Options o = parse(argc, argv);
    const mpi::Comm world = mpi::Comm::world();
    const int rank = world.rank();
    const int ranks = world.size();
    // One mapping for the whole simulation: SMPI runs every rank as a thread of this
    // process (smpi/privatization:no, so this static is shared), one after the other.
    static const Costs costs(o.costs);
    FileSystem fs(o);
    ModelWork work(costs, fs, o, rank);

    // Rank 0's resume journal: the reports since the last one, every journal_seconds.
    std::uint64_t unjournaled = 0;
    double next_journal = o.journal_seconds;
    // Progress on standard error every tenth of the tiles: long simulations are long.
    std::uint64_t reported = 0;
    std::uint64_t next_mark = costs.tiles() / 10;
    const auto wall_start = std::chrono::steady_clock::now();
    const TilesDone done = [&](std::span<const TileReport> tiles, int) {
        reported += tiles.size();
        if (reported >= next_mark && next_mark > 0) {
            std::fprintf(stderr, "sim_run: %llu of %llu tiles reported at %.1f simulated s, %.0f s of wall time\n",
                         static_cast<unsigned long long>(reported), static_cast<unsigned long long>(costs.tiles()),
                         MPI_Wtime(), std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count());
            next_mark += costs.tiles() / 10;
        }
        unjournaled += tiles.size();
        if (MPI_Wtime() >= next_journal) {
            fs.write(16.0 * static_cast<double>(unjournaled) + 4096);
            unjournaled = 0;
            next_journal = MPI_Wtime() + o.journal_seconds;
        }
    };
    world.barrier();
    const double start = MPI_Wtime();
    work.last_end = start;
    work.bucket = o.trace_bucket;
    const ScheduleResult r = run_schedule(world, costs.pending(), work, done, [] { return false; }, o.schedule);
    if (rank == 0) fs.write(16.0 * static_cast<double>(unjournaled) + 4096);
    const double scheduled = MPI_Wtime();
    if (o.trace) {
        // Every rank's time between tiles, summed by second of the run: where the waits are.
        const auto seconds = static_cast<std::size_t>(world.max(static_cast<double>(work.gaps.size())));
        std::vector<double> gaps = work.gaps;
        gaps.resize(seconds, 0.0);
        mpi::check(MPI_Allreduce(MPI_IN_PLACE, gaps.data(), static_cast<int>(gaps.size()), MPI_DOUBLE, MPI_SUM, world.get()),
                   "MPI_Allreduce");
        if (rank == 0) {
            std::fprintf(stderr, "trace waits by %g s of the run (rank-seconds between tiles):", o.trace_bucket);
            for (std::size_t i = 0; i < gaps.size(); ++i) std::fprintf(stderr, " %g:%.1f", static_cast<double>(i) * o.trace_bucket, gaps[i]);
            std::fprintf(stderr, "\n");
        }
        std::fprintf(stderr, "trace rank=%d last_end=%.3f busy=%.3f tiles=%llu blocks=%llu given_back=%llu idle=%.3f leader=%d\n",
                     rank, work.last_end - start, work.busy, static_cast<unsigned long long>(r.stats.tiles),
                     static_cast<unsigned long long>(r.stats.blocks), static_cast<unsigned long long>(r.stats.given_back),
                     r.stats.idle_seconds, r.stats.leader ? 1 : 0);
    }

    // The closing pass: every rank gathers its share of the raw data, compresses it and
    // writes the compressed result. From 64 ranks on, when a share fits in 256 MiB
    // (run/explore.hpp, ExploreSettings::closing_memory_*), the ranks that computed the tiles
    // send them (modelled as one exchange of a share with a rank of another node: every node
    // sends and receives its ranks' shares over its link); otherwise each rank reads its share
    // back from the file system.
    world.barrier();
    const double raw = static_cast<double>(costs.points() * costs.bytes_per_point());
    if (o.io && o.closing) {
        const double share = raw / ranks;
        if (ranks >= 64 && share <= double(std::uint64_t{256} << 20)) {
            // Sizes without data: an S4U message of the share's size to a rank half the
            // machine away, and one from the rank as far the other way.
            const auto to = simgrid::s4u::Mailbox::by_name("closing-" + std::to_string((rank + ranks / 2) % ranks));
            const auto from = simgrid::s4u::Mailbox::by_name("closing-" + std::to_string(rank));
            static char token = 0;
            const simgrid::s4u::CommPtr sent = to->put_async(&token, static_cast<std::uint64_t>(share));
            from->get<char>();
            sent->wait();
        } else {
            fs.read(share);
        }
        smpi_execute(share / (o.compress_mbps * 1e6));
        fs.write(share / o.compress_ratio);
    }
    world.barrier();
    const double end = MPI_Wtime();

    // Reductions, not a gather: SMPI's gather to one rank of 4096 waits on its requests one
    // by one (minutes of wall time).
    const auto reduce = [&](std::vector<double> v, MPI_Op op) {
        mpi::check(MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, op, world.get()),
                   "MPI_Allreduce");
        return v;
    };
    const double last = work.last_end;
    const std::vector<double> mins = reduce({r.stats.computed ? last : 1e300}, MPI_MIN);
    const std::vector<double> maxs =
        reduce({r.stats.computed ? last : 0.0, rank != 0 ? static_cast<double>(r.stats.messages_in) : 0.0, scheduled - start},
               MPI_MAX);
    const std::vector<double> sums = reduce({static_cast<double>(fs.operations), static_cast<double>(r.stats.given_back),
                                             r.stats.computed ? r.stats.idle_seconds : 0.0},
                                            MPI_SUM);
    if (rank == 0) {
        double total = 0;
        for (std::uint64_t t = 0; t < costs.tiles(); ++t) total += costs.cost(t);
        const double first_idle = mins[0], last_busy = maxs[0], leader_messages = maxs[1], schedule_s = maxs[2];
        const double ops = sums[0], given_back = sums[1], idle = sums[2];
        const double predicted = end - start;
        const double ideal = total / ranks;
        std::printf("ranks=%d efficiency=%.4f predicted_s=%.6g ideal_s=%.6g compute_s=%.6g schedule_s=%.6g "
                    "finish_s=%.6g tail_s=%.6g tiles=%llu root_requests=%llu root_messages=%llu "
                    "max_leader_messages=%.0f root_blocks=%zu io_ops=%.0f two_level=%d given_back=%.0f root_asked_back=%llu idle_s_per_rank=%.6g "
                    "reported=%llu\n",
                    ranks, ideal / predicted, predicted, ideal, total, schedule_s, end - scheduled,
                    last_busy - first_idle, static_cast<unsigned long long>(costs.tiles()),
                    static_cast<unsigned long long>(r.stats.requests_in),
                    static_cast<unsigned long long>(r.stats.messages_in), leader_messages, r.stats.handed_out.size(),
                    ops, r.stats.two_level ? 1 : 0, given_back, static_cast<unsigned long long>(r.stats.asked_back),
                    idle / ranks, static_cast<unsigned long long>(reported));
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv)
{
    // Not mpi::Environment: it asks for MPI_THREAD_FUNNELED (the real writer's threads),
    // which SMPI does not provide, and nothing here starts a thread.
    struct Session {
        Session() { superball::mpi::check(MPI_Init(nullptr, nullptr), "MPI_Init"); }
        ~Session() { MPI_Finalize(); }
        Session(const Session&) = delete;
        Session& operator=(const Session&) = delete;
    };
    try {
        const Session session;
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "sim_run: %s\n", e.what());
        return 1;
    }
}
