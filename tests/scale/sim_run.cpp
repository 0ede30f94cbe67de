// The real schedule (src/run/work_pool.cpp over src/run/schedule.cpp and src/mpi/mpi.cpp) under SimGrid's SMPI,
// with counting and writing replaced by cost models. Compressed (the default): a tile costs
// what scale_costs computed from a real result of the job, plus its compression at
// --compress-mbps (smpi_execute, on the rank that counted it); its stored bytes (raw /
// --compress-ratio) travel to their writer in the payloads of the schedule's own report
// messages (rank -> node leader [-> aside to the leader that writes for it] [-> rank 0]:
// the real messages, of the modelled size, over the platform's links); a writer (rank 0, and
// with --writers the node leaders the real pool chooses) copies them (--copy-gbps) and its
// appender (ChunkAppender's two buffers and one write at a time, each write made durable:
// one more operation) writes them through the writer's own client (the platform's
// client_bw, one client a writer) to the shared file system (S4U disk I/O: the disk's
// bandwidth, shared by every operation in flight, after the latency per operation its
// property op_latency states; metadata operations also queue at one metadata server serving
// mds_ops_per_s); a writer other than rank 0 asks rank 0 for file space through the pool's
// real messages; a checkpoint every --journal-seconds (rank 0's appender flushed, the
// journal's dirty range written, the file covered); the finish: the tiles indexed in place
// (--index-us-per-tile of rank 0's CPU each, the index written), the rename, the sidecar.
// Uncompressed runs (--uncompressed): every rank's writer thread writes its tiles at their
// offsets; the same finish without the index. Start-up (MPI_Init and the launch) grows
// with the ranks (StartupLaw below); --resumed charges a resume's reading of the journal,
// its broadcast and the check of every done tile; --lose-node-at crashes the whole job.
// Built with smpicxx and run with smpirun by tests/scale/simulate.sh; prints one line of
// key=value on rank 0.
//
//   smpirun -np P -platform P.xml -hostfile H sim_run COSTS.bin [--node-ranks 32]
//       [--report-seconds 1] [--granule 1] [--block-divisor 2] [--dedicated-root-ranks 64] [--idle-poll 1e-3]
//       [--uncompressed] [--flush-bytes 6291456] [--journal-seconds 10] [--compress-mbps 650] [--compress-ratio 100]
//       [--index-us-per-tile 4] [--copy-gbps 10] [--hash-gbps 10] [--journal-us-per-run 1.95] [--startup-seconds S]
//       [--no-io] [--serve-every 0.05]
//       [--server-serve-every 0.005] [--writers N (0: auto)] [--alignment 1048576] [--resumed]
//       [--trace] [--trace-bucket 1] [--noise SIGMA] [--slow-nodes FRACTION:SPEED] [--seed 1]
//       [--lose-node-at S --lost-record FILE]
#include <fcntl.h>
#include <mpi.h>
#include <smpi/smpi.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <simgrid/s4u/Actor.hpp>
#include <simgrid/s4u/Barrier.hpp>
#include <simgrid/s4u/Comm.hpp>
#include <simgrid/s4u/ConditionVariable.hpp>
#include <simgrid/s4u/Disk.hpp>
#include <simgrid/s4u/Engine.hpp>
#include <simgrid/s4u/Host.hpp>
#include <simgrid/s4u/Mailbox.hpp>
#include <simgrid/s4u/Mutex.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
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
        // The hand-out list holds every tile, or (a resumed run) those not yet done.
        if (size_ < 32 + tiles_ * 16 || (size_ - 32 - tiles_ * 16) % 8 != 0 || (size_ - 32 - tiles_ * 16) / 8 > tiles_) {
            throw std::runtime_error(path + ": truncated");
        }
        pending_count_ = (size_ - 32 - tiles_ * 16) / 8;
        cost_ = reinterpret_cast<const double*>(bytes + 32);
        tile_points_ = reinterpret_cast<const std::uint64_t*>(bytes + 32 + 8 * tiles_);
        pending_ = reinterpret_cast<const std::uint64_t*>(bytes + 32 + 16 * tiles_);
        if (tiles_ > max_run_tiles) throw std::runtime_error(path + ": more tiles than a run takes");
        listed_.assign(pending_, pending_ + pending_count_);
    }
    ~Costs() { ::munmap(data_, size_); }
    Costs(const Costs&) = delete;
    Costs& operator=(const Costs&) = delete;

    std::uint64_t tiles() const { return tiles_; }
    std::uint64_t bytes_per_point() const { return bytes_per_point_; }
    std::uint64_t points() const { return points_; }
    double cost(std::uint64_t t) const { return cost_[t]; }
    std::uint64_t tile_points(std::uint64_t t) const { return tile_points_[t]; }
    std::span<const std::uint64_t> pending() const { return {pending_, pending_count_}; }
    // The hand-out list as the program holds it (job/tiles.hpp ListedTile), shared likewise.
    std::span<const ListedTile> listed() const { return listed_; }

private:
    void* data_ = nullptr;
    std::size_t size_ = 0;
    std::uint64_t tiles_ = 0, bytes_per_point_ = 0, points_ = 0, pending_count_ = 0;
    const double* cost_ = nullptr;
    const std::uint64_t* tile_points_ = nullptr;
    const std::uint64_t* pending_ = nullptr;
    std::vector<ListedTile> listed_;
};

struct Options {
    std::string costs;
    ScheduleSettings schedule;
    bool compressed = true;        // tiles compressed by their rank, appended by rank 0 (the default)
    double flush_bytes = 6 << 20;  // uncompressed: the writer's buffer, 4 MiB of 16-bit counts, 2 MiB of outcomes (run/explore.cpp)
    double batch_bytes = 4 << 20;  // compressed: a rank's tiles leave at least this often (TileWork::should_flush)
    double append_bytes = 8 << 20; // compressed: rank 0's append buffer (ChunkAppender)
    double journal_seconds = 10;
    double compress_mbps = 650;    // shuffle + deflate of a tile, raw MB/s per core (the job's: chunk_ratio.py, codec_speed)
    double compress_ratio = 100;   // raw bytes over stored bytes (the job's: chunk_ratio.py)
    // Rank 0's CPU per tile at the finish (two H5Dwrite_chunk calls, the journal's entry):
    // tests/scale/calibrate.sh measures it (INDEX_US_PER_TILE), simulate.sh passes it.
    double index_us_per_tile = 4;
    // Rank 0 copying payloads (TileBatch::unpack, ChunkAppender::add: two copies a byte), GB/s
    // of payload: calibrate.sh measures it (COPY_GBPS), simulate.sh passes it.
    double copy_gbps = 10;
    // The real program's write calls (strace of `superball explore` at -n 1, 2026-11-27: a
    // 4-tile and a 65536-tile job): creating the partial file, 16 (HDF5's objects, the
    // journal); the finish, 36 of 20.6 KB besides the index and the sidecar (the undo log's
    // header and a copy of every HDF5 metadata write before it, the attributes, the
    // superblock) and one for about 800 tiles of the index (HDF5's fixed-array pages). Counted as calls only: their latency is
    // charged per MiB (client_write), as Lustre's client gathers small writes into RPCs.
    double create_writes = 16;
    double finish_writes = 36;
    double index_tiles_per_write = 800;
    // From mpirun starting to the job parsed on every rank (the launch and MPI_Init);
    // negative: StartupLaw at this many ranks.
    double startup_seconds = -1;
    // How fast a rank computes a done tile's checksum on a resume (XXH3 of its stored
    // bytes): calibrate.sh measures it (HASH_GBPS), simulate.sh passes it.
    double hash_gbps = 10;
    // Rank 0's time to write the places and checksums of a run of consecutive tiles into the
    // journal as it records them (Journal::record, a write each per run): calibrate.sh
    // measures it (JOURNAL_US_PER_RUN, bench_journal: every tile a run of its own),
    // simulate.sh passes it.
    double journal_us_per_run = 1.95;
    // File space is granted to writers in units of this (the job's [run] alignment).
    double alignment = 1 << 20;
    // This run resumes an interrupted one (the costs file holds the tiles left).
    bool resumed = false;
    bool io = true;
    bool trace = false;            // one line per rank on standard error (where the tail comes from)
    double trace_bucket = 1;       // seconds: the waits between tiles summed over ranks by this
    double serve_every = 0.05;     // most compute seconds between two Serve calls (see ModelWork)
    // The same for ranks that serve many (Serve::points below 512: node leaders).
    double server_serve_every = 0.005;
    // Stresses (simulate.sh --noise, --slow-nodes): each tile's compute cost times a
    // lognormal factor of mean 1 and this sigma, drawn from the tile's index and the seed (so
    // the same whichever rank counts it); the nodes whose index a seeded draw puts below
    // slow_fraction count at slow_speed of the others.
    double noise_sigma = 0;
    double slow_fraction = 0;
    double slow_speed = 1;
    std::uint64_t seed = 1;
    // A node lost this many simulated seconds into the compute phase (negative: none): the
    // MPI job dies with it. Rank 0 then writes the tiles its journal recorded at its last
    // checkpoint (u64 each) to lost_record, for the resumed run (scale_costs DONE.bin).
    double lose_node_at = -1;
    std::string lost_record;
};

Options parse(int argc, char** argv)
{
    Options o;
    o.schedule.writers = 0;  // auto, as explore's default
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
        else if (a == "--uncompressed") o.compressed = false;
        else if (a == "--flush-bytes") o.flush_bytes = std::stod(value());
        else if (a == "--journal-seconds") o.journal_seconds = std::stod(value());
        else if (a == "--compress-mbps") o.compress_mbps = std::stod(value());
        else if (a == "--compress-ratio") o.compress_ratio = std::stod(value());
        else if (a == "--index-us-per-tile") o.index_us_per_tile = std::stod(value());
        else if (a == "--copy-gbps") o.copy_gbps = std::stod(value());
        else if (a == "--startup-seconds") o.startup_seconds = std::stod(value());
        else if (a == "--hash-gbps") o.hash_gbps = std::stod(value());
        else if (a == "--journal-us-per-run") o.journal_us_per_run = std::stod(value());
        else if (a == "--writers") o.schedule.writers = std::stoi(value());
        else if (a == "--alignment") o.alignment = std::stod(value());
        else if (a == "--resumed") o.resumed = true;
        else if (a == "--no-io") o.io = false;
        else if (a == "--trace") o.trace = true;
        else if (a == "--trace-bucket") o.trace_bucket = std::stod(value());
        else if (a == "--serve-every") o.serve_every = std::stod(value());
        else if (a == "--server-serve-every") o.server_serve_every = std::stod(value());
        else if (a == "--noise") o.noise_sigma = std::stod(value());
        else if (a == "--slow-nodes") {
            // FRACTION:SPEED
            const std::string v = value();
            const auto colon = v.find(':');
            if (colon == std::string::npos) throw std::runtime_error("--slow-nodes takes FRACTION:SPEED, not " + v);
            o.slow_fraction = std::stod(v.substr(0, colon));
            o.slow_speed = std::stod(v.substr(colon + 1));
            if (o.slow_fraction < 0 || o.slow_fraction > 1 || o.slow_speed <= 0) {
                throw std::runtime_error("--slow-nodes: FRACTION in [0, 1] and SPEED > 0, not " + v);
            }
        }
        else if (a == "--seed") o.seed = std::stoull(value());
        else if (a == "--lose-node-at") o.lose_node_at = std::stod(value());
        else if (a == "--lost-record") o.lost_record = value();
        else if (o.costs.empty() && a.rfind("--", 0) != 0) o.costs = a;
        else throw std::runtime_error("unknown argument " + a);
    }
    if (o.costs.empty()) throw std::runtime_error("usage: sim_run COSTS.bin [options]");
    if (o.lose_node_at >= 0 && o.lost_record.empty()) throw std::runtime_error("--lose-node-at needs --lost-record FILE");
    return o;
}

// The launch and MPI_Init of P ranks, in seconds: 0.226 + 0.2417 sqrt(P), the least-squares
// fit of a + b sqrt(P) to the MPI_Init times measured with Open MPI under srun on LLNL's
// opal (flux-framework/flux-core issue 625: 4.34 s at 128 ranks, 6.60 s at 1024, 9.24 at
// 2048, 17.53 at 4096; the fit's error 1.4 s). The same law gives 67 s at 76,000 ranks,
// where Intel MPI over UCX measured 68-72 s (openucx/ucx issue 6658); a straight line
// through the opal points gives 250 s there, and a logarithm 0.4 s at 64 ranks.
double startup_law(int ranks) { return 0.226 + 0.2417 * std::sqrt(static_cast<double>(ranks)); }

// The one metadata server every rank's metadata operations queue at (the time it is next
// free), shared by every simulated rank (SMPI runs them in one process, privatization off).
double& metadata_server_free_at()
{
    static double t = 0;
    return t;
}

// The shared file system: the disk of the platform's host "fs", which every rank's
// operations share (its bandwidth is the file system's aggregate), after the latency of an
// operation (its property op_latency, in seconds: an RPC and a lock on Lustre). Rank 0's
// own writes (the compressed result, the journal, the finish) also go through its client:
// a disk of its own of the bandwidth the platform's property client_bw states, shared by
// rank 0's writes in flight at once (its main thread's and its appender's), so that a write
// of rank 0 takes as long as the slower of its share of the file system and its share of
// its client.
class FileSystem {
public:
    explicit FileSystem(const Options& o, int rank) : on_(o.io), rank_(rank)
    {
        if (!on_) return;
        host_ = simgrid::s4u::Host::by_name("fs");
        const auto disks = host_->get_disks();
        if (disks.empty()) throw std::runtime_error("the platform's host fs has no disk");
        disk_ = disks.front();
        const char* latency = disk_->get_property("op_latency");
        if (!latency) throw std::runtime_error("the platform's disk of host fs states no op_latency");
        latency_ = std::stod(latency);
        const char* client = disk_->get_property("client_bw");
        if (!client) throw std::runtime_error("the platform's disk of host fs states no client_bw (bytes/s of one client)");
        client_bw_ = std::stod(client);
        const char* mds = disk_->get_property("mds_ops_per_s");
        if (!mds) throw std::runtime_error("the platform's disk of host fs states no mds_ops_per_s (its metadata server)");
        mds_service_ = 1 / std::stod(mds);
    }
    void write(double bytes) { io(bytes, true); }
    void read(double bytes) { io(bytes, false); }
    // An operation on the file system's metadata (create, open, close, rename, unlink): it
    // waits its turn at the metadata server, is served, and pays the round trip.
    void metadata()
    {
        if (!on_) return;
        ++operations;
        const double now = simgrid::s4u::Engine::get_clock();
        double& free_at = metadata_server_free_at();
        const double begin = std::max(now, free_at);
        free_at = begin + mds_service_;
        metadata_wait += begin - now;
        simgrid::s4u::this_actor::sleep_until(free_at + latency_);
    }
    // This rank's write of `bytes` in `ops` operations (each pays the latency once; `ops` 0:
    // one per MiB, the RPCs Lustre makes of a burst of small writes into the client's cache,
    // as HDF5's index pages at the finish): the data cross the rank's client and the file
    // system at once.
    // `calls`: the program's write calls it stands for (the count validate.sh compares).
    void client_write(double bytes, double ops = 1, double calls = 1)
    {
        if (!on_ || bytes <= 0) return;
        if (ops <= 0) ops = std::ceil(bytes / (1 << 20));
        operations += static_cast<std::uint64_t>(ops);
        write_calls += static_cast<std::uint64_t>(calls);
        bytes_written += bytes;
        through_client(bytes, ops, true);
    }
    // This rank's read of `bytes` in `ops` operations (0: one per MiB), through its client.
    void client_read(double bytes, double ops = 0)
    {
        if (!on_ || bytes <= 0) return;
        if (ops <= 0) ops = std::ceil(bytes / (1 << 20));
        operations += static_cast<std::uint64_t>(ops);
        through_client(bytes, ops, false);
    }
    // fdatasync after a write: one more round trip (its data went with the write).
    void sync()
    {
        if (!on_) return;
        ++operations;
        simgrid::s4u::this_actor::sleep_for(latency_);
    }
    std::uint64_t operations = 0;
    // The program's write calls as the model makes them (one a client_write or write) and
    // their bytes: what tests/scale/validate.sh --oversubscribed compares with strace's count
    // of the real run's.
    std::uint64_t write_calls = 0;
    double bytes_written = 0;
    double metadata_wait = 0;  // seconds this rank's metadata operations queued

private:
    void through_client(double bytes, double ops, bool write)
    {
        // One client a rank that writes or reads (a node's own, as each writer is on a node
        // of its own): made at its first use, read and written at client_bw.
        if (!client_) client_ = host_->create_disk("client-" + std::to_string(rank_), client_bw_, client_bw_)->seal();
        simgrid::s4u::this_actor::sleep_for(latency_ * ops);
        const auto n = static_cast<sg_size_t>(std::ceil(bytes));
        const simgrid::s4u::IoPtr a = write ? disk_->write_async(n) : disk_->read_async(n);
        const simgrid::s4u::IoPtr b = write ? client_->write_async(n) : client_->read_async(n);
        a->wait();
        b->wait();
    }
    void io(double bytes, bool write)
    {
        if (!on_ || bytes <= 0) return;
        ++operations;
        if (write) {
            ++write_calls;
            bytes_written += bytes;
        }
        simgrid::s4u::this_actor::sleep_for(latency_);
        const auto n = static_cast<sg_size_t>(std::ceil(bytes));
        if (write) disk_->write(n);
        else disk_->read(n);
    }

    bool on_;
    int rank_;
    double latency_ = 0;
    double client_bw_ = 0;
    double mds_service_ = 0;
    simgrid::s4u::Host* host_ = nullptr;
    simgrid::s4u::Disk* disk_ = nullptr;
    simgrid::s4u::Disk* client_ = nullptr;
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

// A writer of compressed tiles (io/partial_file.cpp, ChunkAppender), step by step: two
// buffers of `capacity` (8 MiB); a batch joins the buffer that fills, which is written at
// once when no write is in flight (or the one in flight is done), else when it holds
// `capacity`; a batch that would take it past `capacity` first sends it off. Sending a
// buffer off starts its write (a thread of its own: here an S4U actor on the writer's host)
// and then waits for the other buffer's write: the writer waits only when a buffer fills
// while the other is still being written (then two writes are in flight for a moment,
// sharing its client). Each write is made durable (fdatasync) before its tiles count as
// written. flush() (a checkpoint, the end) sends the buffer off and waits for it.
class Appender {
public:
    Appender(FileSystem& fs, double capacity)
        : fs_(fs), capacity_(capacity), mutex_(simgrid::s4u::Mutex::create()), done_(simgrid::s4u::ConditionVariable::create())
    {
    }
    Appender(const Appender&) = delete;
    Appender& operator=(const Appender&) = delete;
    ~Appender() { flush(); }

    // `bytes` more, of `tiles` (reported by written() once on disk).
    void add(double bytes, std::span<const std::uint64_t> tiles = {})
    {
        const double now = simgrid::s4u::Engine::get_clock();
        const auto second = static_cast<std::size_t>(now);
        if (second >= ingress_.size()) ingress_.resize(second + 1, 0.0);
        ingress_[second] += bytes;
        if (buffer_[current_] > 0 && buffer_[current_] + bytes > capacity_) issue();
        buffer_[current_] += bytes;
        tiles_[current_].insert(tiles_[current_].end(), tiles.begin(), tiles.end());
        backlog = std::max(backlog, buffer_[0] + buffer_[1]);
        if (buffer_[current_] >= capacity_ || !writing_[1 - current_]) issue();
    }
    void flush()
    {
        issue();
        wait(1 - current_);
    }
    // The tiles written since the last call; a write of what waits when none is in flight.
    std::vector<std::uint64_t> written()
    {
        if (!writing_[1 - current_]) issue();
        return std::exchange(written_, {});
    }
    bool holding() const { return buffer_[0] > 0 || buffer_[1] > 0 || !written_.empty(); }
    // The most payload bytes it received in one second of the run.
    double peak_ingress() const { return ingress_.empty() ? 0.0 : *std::max_element(ingress_.begin(), ingress_.end()); }

    double written_bytes = 0;
    std::uint64_t writes = 0;
    double backlog = 0;      // the most bytes received and not yet written (both buffers)
    double busy_s = 0;       // time with a write in flight
    double held_back_s = 0;  // time its rank waited for a write with a full buffer

private:
    void issue()
    {
        const int b = current_;
        if (buffer_[b] == 0) return;
        writing_[b] = true;
        ++writes;
        if (in_flight_++ == 0) busy_since_ = simgrid::s4u::Engine::get_clock();
        simgrid::s4u::Actor::create("appender-write", simgrid::s4u::this_actor::get_host(),
                                    [this, b, tiles = std::exchange(tiles_[b], {})] {
                                        const double bytes = buffer_[b];
                                        fs_.client_write(bytes);
                                        fs_.sync();
                                        const std::unique_lock lock(*mutex_);
                                        written_bytes += bytes;
                                        written_.insert(written_.end(), tiles.begin(), tiles.end());
                                        buffer_[b] = 0;
                                        writing_[b] = false;
                                        if (--in_flight_ == 0) busy_s += simgrid::s4u::Engine::get_clock() - busy_since_;
                                        done_->notify_all();
                                    });
        current_ = 1 - b;
        const double begin = simgrid::s4u::Engine::get_clock();
        wait(current_);
        held_back_s += simgrid::s4u::Engine::get_clock() - begin;
    }
    void wait(int b)
    {
        std::unique_lock lock(*mutex_);
        while (writing_[b]) done_->wait(lock);
    }

    FileSystem& fs_;
    double capacity_;
    simgrid::s4u::MutexPtr mutex_;
    simgrid::s4u::ConditionVariablePtr done_;
    double buffer_[2] = {0, 0};
    std::vector<std::uint64_t> tiles_[2];
    bool writing_[2] = {false, false};
    int current_ = 0;
    int in_flight_ = 0;
    double busy_since_ = 0;
    std::vector<std::uint64_t> written_;
    std::vector<double> ingress_;  // payload bytes received, by second of the run
};

// A tile's stored bytes: its raw bytes over the job's compression ratio.
double stored_bytes(const Costs& c, const Options& o, std::uint64_t tile)
{
    return static_cast<double>(c.tile_points(tile) * c.bytes_per_point()) / o.compress_ratio;
}

// A node leader that writes (run/work_pool.hpp TileSink, as run/explore.cpp's AppenderSink
// over ChunkAppender): it copies each batch (TileBatch::unpack, ChunkAppender's buffer: two
// copies a byte at --copy-gbps), places its tiles in the file space rank 0 granted it
// (asking for what waits and a stripe, --alignment, ahead), and writes them with an
// appender through its own client.
class SinkModel final : public TileSink {
public:
    SinkModel(FileSystem& fs, const Costs& c, const Options& o) : appender(fs, o.append_bytes), fs_(fs), costs_(c), o_(o) {}

    void add(std::span<const TileReport> tiles, std::span<const std::byte> payload) override
    {
        if (!opened_) {
            opened_ = true;
            fs_.metadata();  // the partial file opened at its first use
        }
        const double copy = 2.0 * static_cast<double>(payload.size()) / (o_.copy_gbps * 1e9);
        smpi_execute(copy);
        copy_s += copy;
        for (const TileReport& t : tiles) {
            const double b = stored_bytes(costs_, o_, t.tile);
            waiting_.push_back({t.tile, b});
            waiting_bytes_ += b;
        }
        peak_bytes = std::max(peak_bytes, waiting_bytes_ + appender.backlog + static_cast<double>(payload.size()));
        place();
    }
    std::uint64_t wanted() const override
    {
        const double need = waiting_bytes_ + o_.alignment;
        return need > held_ ? static_cast<std::uint64_t>(std::ceil(need - held_)) : 0;
    }
    void grant(std::uint64_t, std::uint64_t bytes) override
    {
        held_ += static_cast<double>(bytes);
        place();
    }
    std::vector<AppendedTile> written() override
    {
        std::vector<AppendedTile> out;
        for (const std::uint64_t t : appender.written()) {
            out.push_back({t, t, {0, static_cast<std::uint64_t>(stored_bytes(costs_, o_, t)), 0}});
        }
        return out;
    }
    bool holding() const override { return !waiting_.empty() || appender.holding(); }
    bool full() const override { return waiting_bytes_ > o_.append_bytes; }

    Appender appender;
    double copy_s = 0;
    double peak_bytes = 0;  // the most it held at once: waiting, in its buffers, a message

private:
    void place()
    {
        while (!waiting_.empty() && waiting_.front().second <= held_) {
            const auto [tile, bytes] = waiting_.front();
            waiting_.pop_front();
            held_ -= bytes;
            waiting_bytes_ -= bytes;
            appender.add(bytes, std::span<const std::uint64_t>(&tile, 1));
        }
    }

    FileSystem& fs_;
    const Costs& costs_;
    const Options& o_;
    bool opened_ = false;
    std::deque<std::pair<std::uint64_t, double>> waiting_;
    double waiting_bytes_ = 0;
    double held_ = 0;
};

// Counting replaced by smpi_execute of the tile's modelled cost, in pieces with the Serve
// callback between them. The real counter calls it every Serve::points points (512, 64
// on a node leader); so does the model where that many points cost more than
// --serve-every seconds (--server-serve-every on a leader: a rank holding heavy tiles
// answers as late as the real one), and every --serve-every seconds of compute elsewhere
// (fewer events: answers come later than in the real run by at most that, never sooner).
// Compressed (the default): the tile's compression costs its raw bytes at
// --compress-mbps, and its stored bytes (raw / --compress-ratio) join the rank's batch,
// which leaves with its reports at least every report period, or when it holds
// --batch-bytes: the payload of the real message is that many bytes. Uncompressed: as the
// writer does, tiles buffered until ~6 MiB, a tile that does not follow the last, or a
// flush, then one write to /wall_bounces and one to /outcome on the writer thread.
// A uniform draw in [0, 1) from (a, b): splitmix64, so that stresses are reproducible and do
// not depend on the order SMPI runs the ranks in.
double uniform(std::uint64_t a, std::uint64_t b)
{
    std::uint64_t z = a * 0x9E3779B97F4A7C15ULL + b + 0x632BE59BD9B4E5ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
}

// A lognormal factor of mean 1 and log-deviation `sigma`, from two draws of (seed, i)
// (Box-Muller).
double lognormal(double sigma, std::uint64_t seed, std::uint64_t i)
{
    const double u1 = std::max(uniform(seed, 2 * i), 1e-300), u2 = uniform(seed, 2 * i + 1);
    const double z = std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
    return std::exp(sigma * z - sigma * sigma / 2);
}

// The stresses' factor on a tile's compute time on `rank`: noise (lognormal, mean 1) of the
// tile and of the rank (a slow core stays slow: Acun, Miller and Kale measured up to 16 %
// between the processors of one cluster under Turbo Boost, ICS 2016), times the slowdown
// of a slow node.
double stress_factor(const Options& o, std::uint64_t tile, int rank)
{
    double f = 1;
    if (o.noise_sigma > 0) {
        f *= lognormal(o.noise_sigma, o.seed, tile);
        f *= lognormal(o.noise_sigma, o.seed + 0x7a4c, static_cast<std::uint64_t>(rank));
    }
    if (o.slow_fraction > 0) {
        const auto node = static_cast<std::uint64_t>(rank / std::max(1, o.schedule.node_ranks));
        if (uniform(o.seed + 0x51077, node) < o.slow_fraction) f /= o.slow_speed;
    }
    return f;
}

class ModelWork final : public TileWork {
public:
    ModelWork(const Costs& c, FileSystem& fs, const Options& o, int rank)
        : rank_(rank),
          costs_(c),
          writer_(o.compressed ? std::nullopt : std::make_optional<WriterThread>(fs, rank)),
          options_(o),
          flush_bytes_(o.flush_bytes),
          serve_every_(o.serve_every),
          server_serve_every_(o.server_serve_every),
          io_(o.io)
    {
    }

    void compute(std::uint64_t tile, const Serve& serve) override
    {
        const std::uint64_t points = costs_.tile_points(tile);
        const double raw = static_cast<double>(points * costs_.bytes_per_point());
        const double compress = options_.compressed ? raw / (options_.compress_mbps * 1e6) : 0.0;
        const double cost = (costs_.cost(tile) + compress) * stress_factor(options_, tile, rank_);
        // Time since the last tile (waiting, scheduling, writing), by second of the run.
        const double begin = MPI_Wtime();
        if (begin > last_end) {
            const auto second = static_cast<std::size_t>(std::max(0.0, last_end / bucket));
            if (second >= gaps.size()) gaps.resize(second + 1, 0.0);
            gaps[second] += begin - last_end;
        }
        // Uncompressed: a tile that does not follow the buffered ones, or a full buffer, is
        // written first.
        if (!options_.compressed && buffered_points_ > 0 && (tile != next_tile_ || buffered_bytes_ + raw > flush_bytes_)) {
            issue();
        }
        // A rank serving many calls Serve more often (schedule.hpp, Serve::points).
        const double every = serve.points < 512 ? server_serve_every_ : serve_every_;
        const auto wanted = static_cast<std::uint64_t>(std::ceil(cost / every));
        const std::uint64_t most = std::max<std::uint64_t>(1, points / std::max<std::size_t>(1, serve.points));
        const int pieces = static_cast<int>(std::clamp<std::uint64_t>(wanted, 1, most));
        for (int i = 0; i < pieces; ++i) {
            smpi_execute(cost / pieces);
            busy += cost / pieces;  // as it goes: what a crash loses of a tile in progress
            if (shared_busy) *shared_busy = busy;
            if (serve) serve();
        }
        ++tiles;
        last_end = MPI_Wtime();
        next_tile_ = tile + 1;
        buffered_points_ += points;
        buffered_.push_back(tile);
        buffered_bytes_ += options_.compressed ? raw / options_.compress_ratio : raw;
        max_batch_bytes = std::max(max_batch_bytes, buffered_bytes_);
    }

    Flushed flush() override
    {
        Flushed out;
        if (options_.compressed) {
            for (const std::uint64_t t : buffered_) out.reports.push_back({t, t});
            // The message TileBatch::pack makes: the tile count, 4 words a tile (tile,
            // checksum, the sizes of its stored counts and outcomes), the stored bytes.
            out.payload.resize(static_cast<std::size_t>(std::ceil(buffered_bytes_)) + 8 + 32 * buffered_.size());
            payload_bytes += static_cast<double>(out.payload.size());
            buffered_.clear();
            buffered_points_ = 0;
            buffered_bytes_ = 0;
            return out;
        }
        issue();
        writer_->wait();
        for (const std::uint64_t t : written_) out.reports.push_back({t, t});
        written_.clear();
        return out;
    }

    bool should_flush() const override { return options_.compressed && buffered_bytes_ >= options_.batch_bytes; }

    double busy = 0;
    std::uint64_t tiles = 0;
    double payload_bytes = 0;  // compressed bytes this rank sent
    double max_batch_bytes = 0;  // the most compressed bytes it held before sending them
    double* shared_busy = nullptr;  // where `busy` is copied for a crash to count
    double last_end = 0;       // set to the start of the run before the first tile
    double bucket = 1;         // of the gaps, in seconds
    std::vector<double> gaps;  // seconds between tiles (and before the first), by bucket of the run their wait began

private:
    void issue()
    {
        if (buffered_points_ == 0) return;
        const double count_bytes = static_cast<double>(costs_.bytes_per_point() - 1);
        const double p = static_cast<double>(buffered_points_);
        if (io_) writer_->issue({p * count_bytes, p});
        written_.insert(written_.end(), buffered_.begin(), buffered_.end());
        buffered_.clear();
        buffered_points_ = 0;
        buffered_bytes_ = 0;
    }

    int rank_;
    const Costs& costs_;
    std::optional<WriterThread> writer_;  // uncompressed only: an actor (and its stack) a rank
    const Options& options_;
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

// The modelled memory of a rank beyond its counting's own buffers (explore's, bytes): the
// hand-out list every rank holds (4 bytes a pending tile: ListedTile); a resume's done
// flags (a bit a tile) and the rank's share of the done tiles' checksums and places (40
// bytes each: tile, checksum, place), on rank 0 also the share it is sending (32 bytes a
// done tile of it) and the window of the journal it reads them from (2 MiB); on rank 0 the
// journal's done flags (a byte a tile: the checksums and places are written to the file as
// tiles are recorded, Journal), its appender's two buffers and the largest message it takes; a rank's compressed tiles
// before it sends them and their packed copy; a writer's waiting tiles, buffers and the
// largest message; a leader passing its node's tiles on, its outbox of up to 8 MiB and the
// message it makes of it.
struct Memory {
    double list = 0, resume = 0, journal = 0, buffers = 0;
    double total() const { return list + resume + journal + buffers; }
};

// The model's own meetings of every rank (the program's collectives stay real: run_schedule's
// and the topology's): a SimGrid barrier, which simulates no message, then what a tree
// collective costs the real program, 2 log2(P) link latencies (1 us, cluster.xml). SMPI's
// collectives at 16384 ranks kept the simulator several minutes each (thousands of flows
// at once on shared links, the network model solved again as each ends): the dozen at the
// start and end of a run took longer than its counting. Values the ranks give to be
// reduced go through memory: SMPI runs the ranks in one process (smpi/privatization:no).
class Meeting {
public:
    explicit Meeting(int ranks) : ranks_(ranks), barrier_(shared(ranks)) {}
    void meet() const
    {
        barrier_->wait();
        simgrid::s4u::this_actor::sleep_for(2 * std::ceil(std::log2(std::max(2, ranks_))) * 1e-6);
    }
    // Every rank's `mine` (the same length on every rank), after a meeting: rank r's at [r].
    const std::vector<std::vector<double>>& gather(int rank, std::vector<double> mine) const
    {
        static std::vector<std::vector<double>> board;
        if (board.size() != static_cast<std::size_t>(ranks_)) board.resize(static_cast<std::size_t>(ranks_));
        board[static_cast<std::size_t>(rank)] = std::move(mine);
        meet();
        return board;
    }

private:
    static simgrid::s4u::BarrierPtr shared(int ranks)
    {
        static const simgrid::s4u::BarrierPtr b = simgrid::s4u::Barrier::create(static_cast<unsigned>(ranks));
        return b;
    }
    int ranks_;
    simgrid::s4u::BarrierPtr barrier_;
};

int run(int argc, char** argv)
{
    const Options o = parse(argc, argv);
    const mpi::Comm world = mpi::Comm::world();
    const int rank = world.rank();
    const int ranks = world.size();
    const Meeting meeting(ranks);
    // One mapping for the whole simulation: SMPI runs every rank as a thread of this
    // process (smpi/privatization:no, so this static is shared), one after the other.
    static const Costs costs(o.costs);
    // Every rank's compute time so far, for a crash (which counts what each had computed):
    // shared likewise.
    static std::vector<double> busy_by_rank;
    FileSystem fs(o, rank);
    ModelWork work(costs, fs, o, rank);
    if (rank == 0) busy_by_rank.assign(static_cast<std::size_t>(ranks), 0.0);
    meeting.meet();
    work.shared_busy = &busy_by_rank[static_cast<std::size_t>(rank)];
    const double tiles = static_cast<double>(costs.tiles());
    const double pending = static_cast<double>(costs.pending().size());
    const double done_tiles = tiles - pending;  // by the runs before (a resume)
    const double startup = o.startup_seconds >= 0 ? o.startup_seconds : startup_law(ranks);
    // Rank 0's record of the tiles reported done, and how many of them its journal held at
    // the last checkpoint (what a resume finds after a crash).
    std::vector<std::uint64_t> reported_tiles;
    std::size_t recorded = 0;

    // The start (run/explore.cpp, io/partial_file.cpp create_partial). A new run: rank 0
    // creates the partial file (create, the HDF5 objects and the journal's datasets, a flush:
    // compressed, 14 KB and 35 bytes a tile in 16 write calls, measured as
    // Options::create_writes was; 9 bytes a tile uncompressed). A resume (--resumed): rank 0
    // looks for an undo log, opens the partial file with HDF5 and reads its journal
    // (ResultReader: the done flags, and compressed the places, checked, and read again with
    // the flags for the data's ranges, 51 bytes a tile; then the record of each rank's share
    // of the done tiles, read a window of tiles at a time, 32 bytes a tile: 83 bytes a tile
    // compressed, 9 uncompressed); the done flags, a bit a tile, are broadcast to every rank
    // (charged as a scatter and an allgather, van de Geijn's large broadcast: 2 B / link
    // bandwidth, plus a latency per level of the tree), and each rank is sent its share of
    // the done tiles' checksums and places (32 bytes a done tile, 8 uncompressed, all of
    // them leaving rank 0's link, one message a rank after the other); each
    // rank opens the file, reads its share of the done tiles one pread each through its
    // client and hashes them (--hash-gbps), and the ranks gather what they found. Then the ranks
    // that write open the file (POSIX: a rank opens it when it first uses it; uncompressed,
    // every rank writes).
    const double journal_bytes_per_tile = o.compressed ? 35.0 : 9.0;
    const double journal_read_per_tile = o.compressed ? 83.0 : 9.0;
    const double t0 = MPI_Wtime();
    double restart_s = 0;
    if (!o.resumed) {
        if (rank == 0) {
            fs.metadata();
            const double bytes = journal_bytes_per_tile * tiles + 14336;
            fs.client_write(bytes, 0, o.create_writes);
            fs.metadata();
        }
        meeting.meet();
    } else {
        static std::vector<std::uint64_t> done;  // the done tiles, in order: rank 0's list, every rank's copy
        if (rank == 0) {
            fs.metadata();  // the undo log looked for
            fs.metadata();  // the HDF5 open
            fs.client_read(journal_read_per_tile * tiles + 14336);
            fs.metadata();  // the close
            std::vector<bool> pend(costs.tiles(), false);
            for (const std::uint64_t t : costs.pending()) pend[t] = true;
            done.clear();
            for (std::uint64_t t = 0; t < costs.tiles(); ++t) {
                if (!pend[t]) done.push_back(t);
            }
        }
        meeting.meet();
        const double levels = std::ceil(std::log2(std::max(2, ranks)));
        const double bcast = levels * 2e-6 + 2 * (tiles / 8) / 12.5e9;
        const double scatter = ranks * 2e-6 + (o.compressed ? 32 : 8) * done_tiles / 12.5e9;
        simgrid::s4u::this_actor::sleep_for(bcast + scatter);
        const auto n = static_cast<std::uint64_t>(done.size());
        const std::uint64_t begin = n * static_cast<std::uint64_t>(rank) / static_cast<std::uint64_t>(ranks);
        const std::uint64_t end = n * static_cast<std::uint64_t>(rank + 1) / static_cast<std::uint64_t>(ranks);
        double bytes = 0;
        for (std::uint64_t i = begin; i < end; ++i) {
            bytes += o.compressed ? stored_bytes(costs, o, done[i])
                                  : static_cast<double>(costs.tile_points(done[i]) * costs.bytes_per_point());
        }
        if (end > begin) {
            if (rank != 0) fs.metadata();  // its open
            fs.client_read(bytes, static_cast<double>(end - begin));
            smpi_execute(bytes / (o.hash_gbps * 1e9));
        }
        meeting.meet();
        restart_s = MPI_Wtime() - t0;
    }

    // Who writes (the real pool's choice, src/run/work_pool.cpp): rank 0, and the node
    // leaders it makes writers; they open the file. Rank 0 grants them file space in stripes.
    const int writer_count = o.compressed ? schedule_writers(world, o.schedule) : 1;
    std::optional<SinkModel> sink;
    Writers writing;
    double next_free = 0;
    std::uint64_t root_grants = 0;
    if (o.compressed && writer_count > 1 && rank != 0) writing.sink = &sink.emplace(fs, costs, o);
    const bool opens = !o.compressed || rank == 0;  // the sinks' writers open the file at their first write, below
    if (opens && !(o.resumed && rank != 0)) fs.metadata();
    meeting.meet();

    // Rank 0: the appender of compressed tiles; the tiles it records write their places and
    // checksums into the journal (Journal::record: each run of consecutive tiles of a batch
    // --journal-us-per-run of rank 0's CPU and two write calls, one uncompressed; 32 bytes a
    // tile, 8 uncompressed, gathered by the client's cache and charged at the next
    // checkpoint); a checkpoint every journal_seconds (explore.cpp
    // `checkpoint`): the appender flushed (its last write waited for), the journal's done
    // flags written (Journal::checkpoint: the range from the first to the last tile
    // recorded since the last one, a byte a tile, in one write; with interleaved hand-out
    // that range is most of the grid), then the file covered (PlacedChunks::cover, rank 0 alone: the undo
    // log created and its header written, the HDF5 open, its superblock read, logged and
    // rewritten, the close, the log unlinked: four small operations and four on metadata).
    std::optional<Appender> appender;
    if (rank == 0 && o.compressed && o.io) appender.emplace(fs, o.append_bytes);
    std::uint64_t dirty_begin = costs.tiles(), dirty_end = 0;
    std::uint64_t journal_unflushed = 0;  // tiles recorded since the last checkpoint
    std::uint64_t journal_runs = 0;       // of which runs of consecutive tiles
    double next_journal = MPI_Wtime() + o.journal_seconds;
    double checkpoint_s = 0;
    const auto checkpoint = [&](bool cover) {
        const double begin = MPI_Wtime();
        if (appender) appender->flush();
        if (dirty_end > dirty_begin) {
            const auto n = static_cast<double>(dirty_end - dirty_begin);
            const auto m = static_cast<double>(journal_unflushed);
            fs.client_write((o.compressed ? 32 : 8) * m, 0, (o.compressed ? 2 : 1) * static_cast<double>(journal_runs));
            fs.client_write(n, 0);
            if (cover && appender) {
                fs.metadata();
                for (int i = 0; i < 4; ++i) fs.client_write(512);
                fs.metadata();
                fs.metadata();
                fs.metadata();
            }
        }
        dirty_begin = costs.tiles();
        dirty_end = 0;
        journal_unflushed = journal_runs = 0;
        recorded = reported_tiles.size();
        checkpoint_s += MPI_Wtime() - begin;
    };
    // Progress on standard error every tenth of the tiles: long simulations are long.
    std::uint64_t reported = 0;
    std::uint64_t next_mark = costs.pending().size() / 10;
    const auto wall_start = std::chrono::steady_clock::now();
    double copy_s = 0;
    const auto record = [&](std::uint64_t tile) {
        ++journal_unflushed;
        dirty_begin = std::min(dirty_begin, tile);
        dirty_end = std::max(dirty_end, tile + 1);
        reported_tiles.push_back(tile);
        if (++reported >= next_mark && next_mark > 0) {
            std::fprintf(stderr, "sim_run: %llu of %zu tiles reported at %.1f simulated s, %.0f s of wall time\n",
                         static_cast<unsigned long long>(reported), costs.pending().size(), MPI_Wtime(),
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count());
            next_mark += costs.pending().size() / 10;
        }
    };
    // Journal::record's writes, on rank 0's main thread.
    double journal_s = 0;
    const auto journal_cpu = [&](auto tiles_recorded) {
        std::uint64_t runs = 0;
        for (std::size_t i = 0; i < tiles_recorded.size(); ++i) {
            if (i == 0 || tiles_recorded[i].tile != tiles_recorded[i - 1].tile + 1) ++runs;
        }
        journal_runs += runs;
        const double cpu = static_cast<double>(runs) * o.journal_us_per_run * 1e-6;
        if (cpu <= 0 || !o.io) return;
        smpi_execute(cpu);
        journal_s += cpu;
    };
    const auto maybe_checkpoint = [&] {
        if (MPI_Wtime() >= next_journal) {
            next_journal = MPI_Wtime() + o.journal_seconds;
            checkpoint(true);
        }
    };
    const TilesDone done = [&](std::span<const TileReport> tiles_done, int, std::span<const std::byte> payload) {
        for (const TileReport& t : tiles_done) record(t.tile);
        journal_cpu(tiles_done);
        if (appender) {
            // TileBatch::unpack's copy and ChunkAppender::add's, on rank 0's main thread.
            const double copy = 2.0 * static_cast<double>(payload.size()) / (o.copy_gbps * 1e9);
            smpi_execute(copy);
            copy_s += copy;
            appender->add(static_cast<double>(payload.size()));
        }
        maybe_checkpoint();
    };
    if (rank == 0 && writer_count > 1) {
        writing.placed = [&](std::span<const AppendedTile> placed) {
            for (const AppendedTile& t : placed) record(t.tile);
            journal_cpu(placed);
            maybe_checkpoint();
        };
        writing.grant = [&](std::uint64_t bytes) {
            const double unit = o.alignment;
            const FileSpace f{static_cast<std::uint64_t>(next_free),
                              static_cast<std::uint64_t>(std::ceil(static_cast<double>(bytes) / unit) * unit)};
            next_free += static_cast<double>(f.bytes);
            ++root_grants;
            return f;
        };
    }
    meeting.meet();
    const double start = MPI_Wtime();
    work.last_end = start;
    work.bucket = o.trace_bucket;
    // A lost node: the job dies with it at that moment, every rank at once (an actor of rank
    // 0's sleeps until then and ends the simulation): what its journal recorded at the last
    // checkpoint stands, everything else counted is lost. Nothing after it is counted.
    if (o.lose_node_at >= 0 && rank == 0) {
        simgrid::s4u::Actor::create("node-lost", simgrid::s4u::this_actor::get_host(), [&] {
            simgrid::s4u::this_actor::sleep_until(start + o.lose_node_at);
            double busy = 0, kept = 0;
            for (const double b : busy_by_rank) busy += b;
            for (std::size_t i = 0; i < recorded; ++i) {
                const std::uint64_t t = reported_tiles[i];
                const double raw = static_cast<double>(costs.tile_points(t) * costs.bytes_per_point());
                kept += costs.cost(t) + (o.compressed ? raw / (o.compress_mbps * 1e6) : 0.0);
            }
            std::FILE* f = std::fopen(o.lost_record.c_str(), "wb");
            const std::size_t wrote = f ? std::fwrite(reported_tiles.data(), sizeof(std::uint64_t), recorded, f) : 0;
            if (f == nullptr || std::fclose(f) != 0 || wrote != recorded) {
                std::fprintf(stderr, "sim_run: cannot write %s\n", o.lost_record.c_str());
                std::_Exit(1);
            }
            std::printf("lost_node_at_s=%.6g lost_at_s=%.6g startup_s=%.6g recorded_tiles=%zu reported_tiles=%zu "
                        "pending_tiles=%zu work_s=%.6g recorded_work_s=%.6g lost_work_s=%.6g\n",
                        o.lose_node_at, startup + (MPI_Wtime() - t0), startup, recorded, reported_tiles.size(),
                        costs.pending().size(), busy, kept, busy - kept);
            std::fflush(stdout);
            std::fflush(stderr);
            std::_Exit(0);
        })->daemonize();
    }
    const ScheduleResult r = run_schedule(world, costs.listed(), work, done, [] { return false; }, o.schedule, writing);
    double scheduled = 0;
    for (const std::vector<double>& t : meeting.gather(rank, {MPI_Wtime()})) scheduled = std::max(scheduled, t[0]);
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

    // The end (run/explore.cpp): rank 0's last write and the journal (no cover: the finish
    // follows), every rank closes the file, then rank 0 alone makes it the result
    // (io/final_result.cpp): the HDF5 open with the undo log (as a cover), every tile
    // indexed where it lies (--index-us-per-tile of rank 0's CPU a tile, measured by
    // calibrate.sh, and the index written: two entries of 15 bytes a tile, HDF5's fixed-array
    // pages of 1024 entries written in a burst at the close), the attributes, the close, the
    // rename, the undo log unlinked, the sidecar (create, write, close).
    double finish_start = 0;
    if (rank == 0) {
        checkpoint(false);
        finish_start = MPI_Wtime();
    }
    meeting.meet();
    if (rank == 0 && o.io) {
        fs.metadata();           // the undo log
        fs.metadata();           // the HDF5 open
        // The superblock read and logged, the attributes, /progress unlinked, every write
        // logged to the undo log first.
        fs.client_write(20600, 2, o.finish_writes);
        if (o.compressed) {
            smpi_execute(o.index_us_per_tile * 1e-6 * tiles);
            const double calls = std::ceil(tiles / o.index_tiles_per_write);
            fs.client_write(30.0 * tiles, 0, calls);
        }
        fs.metadata();           // close
        fs.metadata();           // rename
        fs.metadata();           // the undo log unlinked
        fs.metadata();           // the sidecar: create, write, close
        fs.client_write(1024);
        fs.metadata();
    }
    meeting.meet();
    const double end = MPI_Wtime();
    const double written = appender ? appender->written_bytes : 0.0;
    const double writes = appender ? static_cast<double>(appender->writes) : 0.0;
    const double backlog = appender ? appender->backlog : 0.0;
    const double writer_busy = appender ? appender->busy_s : 0.0;
    const double held_back = appender ? appender->held_back_s : 0.0;
    const double peak_ingress = appender ? appender->peak_ingress() : 0.0;
    appender.reset();
    const bool sink_wrote = sink && r.stats.writer;
    const double sink_bytes = sink_wrote ? sink->appender.written_bytes : 0.0;
    const double sink_held_back = sink_wrote ? sink->appender.held_back_s : 0.0;
    const double sink_peak_ingress = sink_wrote ? sink->appender.peak_ingress() : 0.0;

    // The memory model (Memory above), this rank's.
    Memory mem;
    mem.list = 4 * pending;
    mem.resume = o.resumed ? tiles / 8 + 40 * done_tiles / ranks + (rank == 0 ? 32 * done_tiles / ranks + (2 << 20) : 0.0) : 0.0;
    mem.journal = rank == 0 ? tiles : 0.0;
    const double message = 8 << 20;  // the largest message a server takes: a leader's 8 MiB of its node's
    mem.buffers = 2 * work.max_batch_bytes;
    if (rank == 0 && o.compressed) mem.buffers += 2 * o.append_bytes + message;
    if (sink_wrote) mem.buffers += std::max(sink->peak_bytes, 2 * o.append_bytes) + message;
    if (r.stats.leader && rank != 0 && !r.stats.writer && o.compressed) mem.buffers += 2 * message;

    // Every rank's figures reduced (Meeting::gather: in memory, not SMPI's collectives).
    const auto reduce = [&](const std::vector<std::vector<double>>& all, std::size_t at, std::size_t n, auto op) {
        std::vector<double> v(all[0].begin() + static_cast<std::ptrdiff_t>(at), all[0].begin() + static_cast<std::ptrdiff_t>(at + n));
        for (const std::vector<double>& r : all) {
            for (std::size_t k = 0; k < n; ++k) v[k] = op(v[k], r[at + k]);
        }
        return v;
    };
    const double last = work.last_end;
    const double tiles_here = static_cast<double>(r.stats.tiles);
    const std::vector<double> mine_min{r.stats.computed ? last : 1e300, r.stats.computed ? tiles_here : 1e300};
    const std::vector<double> mine_max{r.stats.computed ? last : 0.0, rank != 0 ? static_cast<double>(r.stats.messages_in) : 0.0,
                                       scheduled - start, r.stats.computed ? tiles_here : 0.0, sink_bytes, sink_held_back,
                                       sink_peak_ingress, mem.total(), rank != 0 ? mem.total() : 0.0, fs.metadata_wait,
                                       r.stats.space_wait_seconds};
    const std::vector<double> mine_sum{static_cast<double>(fs.operations), static_cast<double>(r.stats.given_back),
                                       r.stats.computed ? r.stats.idle_seconds : 0.0, work.payload_bytes,
                                       r.stats.computed ? 1.0 : 0.0, static_cast<double>(fs.write_calls), fs.bytes_written,
                                       sink_bytes, sink ? sink->copy_s : 0.0};
    std::vector<double> mine = mine_min;
    mine.insert(mine.end(), mine_max.begin(), mine_max.end());
    mine.insert(mine.end(), mine_sum.begin(), mine_sum.end());
    const std::vector<std::vector<double>>& all = meeting.gather(rank, std::move(mine));
    if (rank != 0) return 0;  // rank 0 reduces and reports
    const auto least = [](double a, double b) { return std::min(a, b); };
    const auto most = [](double a, double b) { return std::max(a, b); };
    const std::vector<double> mins = reduce(all, 0, mine_min.size(), least);
    const std::vector<double> maxs = reduce(all, mine_min.size(), mine_max.size(), most);
    const std::vector<double> sums = reduce(all, mine_min.size() + mine_max.size(), mine_sum.size(), std::plus<>());
    {  // the line rank 0 prints
        double total = 0;
        for (const std::uint64_t t : costs.pending()) total += costs.cost(t);  // (every tile, unless resumed)
        const double first_idle = mins[0], last_busy = maxs[0], leader_messages = maxs[1], schedule_s = maxs[2];
        const double writer_bytes_max = maxs[4], writer_held_back = maxs[5], writer_peak_ingress = maxs[6];
        const double rank_mib = maxs[7] / (1 << 20), other_mib = maxs[8] / (1 << 20), metadata_wait = maxs[9];
        const double space_wait = maxs[10];
        const double ops = sums[0], given_back = sums[1], idle = sums[2], payload = sums[3], computing = sums[4],
                     write_calls = sums[5], bytes_written = sums[6], by_writers = sums[7], writers_copy = sums[8];
        const double tiles_min = mins[1], tiles_max = maxs[3];
        // From mpirun starting (the start-up) to the result renamed; and the compute phase,
        // from the first tile handed out to the last done, as explore reports it.
        const double end_to_end = startup + (end - t0);
        const double ideal = total / ranks;
        std::printf("ranks=%d efficiency=%.4f end_to_end=%.4f predicted_s=%.6g ideal_s=%.6g compute_s=%.6g schedule_s=%.6g "
                    "startup_s=%.6g create_s=%.6g restart_s=%.6g finish_s=%.6g after_compute_s=%.6g tail_s=%.6g tiles=%llu "
                    "root_requests=%llu root_messages=%llu max_leader_messages=%.0f root_blocks=%zu io_ops=%.0f two_level=%d "
                    "given_back=%.0f root_asked_back=%llu idle_s_per_rank=%.6g reported=%llu compressed=%d payload_bytes=%.6g "
                    "written_by_root=%.6g root_writes=%.0f writer_busy_s=%.6g writer_backlog_bytes=%.6g root_held_back_s=%.6g "
                    "root_peak_ingress_bytes_per_s=%.6g root_copy_s=%.6g root_journal_s=%.6g checkpoint_s=%.6g computing_ranks=%.0f tiles_min=%.0f "
                    "tiles_max=%.0f write_calls=%.0f bytes_written=%.0f writers=%d written_by_writers=%.6g "
                    "writer_bytes_max=%.6g writer_held_back_max_s=%.6g writer_peak_ingress_bytes_per_s=%.6g writers_copy_s=%.6g "
                    "root_grants=%llu metadata_wait_max_s=%.6g writer_space_wait_max_s=%.6g rank_mib=%.1f root_mib=%.1f "
                    "other_rank_mib=%.1f\n",
                    ranks, ideal / (scheduled - start), ideal / end_to_end, end_to_end, ideal, total, schedule_s, startup,
                    start - t0 - restart_s, restart_s, end - finish_start, end - scheduled, last_busy - first_idle,
                    static_cast<unsigned long long>(costs.tiles()), static_cast<unsigned long long>(r.stats.requests_in),
                    static_cast<unsigned long long>(r.stats.messages_in), leader_messages, r.stats.handed_out.size(), ops,
                    r.stats.two_level ? 1 : 0, given_back, static_cast<unsigned long long>(r.stats.asked_back), idle / ranks,
                    static_cast<unsigned long long>(reported), o.compressed ? 1 : 0, payload, written, writes, writer_busy,
                    backlog, held_back, peak_ingress, copy_s, journal_s, checkpoint_s, computing, tiles_min, tiles_max, write_calls,
                    bytes_written, writer_count, by_writers, writer_bytes_max, writer_held_back, writer_peak_ingress, writers_copy,
                    static_cast<unsigned long long>(root_grants), metadata_wait, space_wait, rank_mib, mem.total() / (1 << 20),
                    other_mib);
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
