#include "schedule.hpp"

#include <algorithm>

namespace superball {

namespace {

constexpr int tag_request = 1;  // worker -> 0: {stop flag, n, then n (tile, checksum) pairs}
constexpr int tag_assign = 2;   // 0 -> worker: {first, count} of a block; count 0: no more

// Guided self-scheduling: a block of remaining / (2 P) entries, at least one, a multiple
// of the granule while that leaves blocks of at least one granule.
std::uint64_t block_size(std::uint64_t remaining, int ranks, std::uint64_t granule)
{
    std::uint64_t n = std::max<std::uint64_t>(1, remaining / (2 * static_cast<std::uint64_t>(ranks)));
    if (granule > 1 && n >= granule) n -= n % granule;
    return std::min(n, remaining);
}

std::vector<std::uint64_t> pack(bool stop, const std::vector<TileReport>& reports)
{
    std::vector<std::uint64_t> msg{stop ? 1u : 0u, reports.size()};
    for (const TileReport& r : reports) msg.insert(msg.end(), {r.tile, r.checksum});
    return msg;
}

void worker(const mpi::Comm& comm, std::span<const std::uint64_t> pending, TileWork& work, const StopRequested& stop)
{
    const Serve nothing;
    std::vector<TileReport> reports;
    for (;;) {
        const std::vector<std::uint64_t> msg = pack(stop(), reports);
        mpi::check(MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_UINT64_T, 0, tag_request, comm.get()),
                   "MPI_Send");
        std::uint64_t block[2] = {0, 0};
        mpi::check(MPI_Recv(block, 2, MPI_UINT64_T, 0, tag_assign, comm.get(), MPI_STATUS_IGNORE), "MPI_Recv");
        if (block[1] == 0) return;
        for (std::uint64_t i = block[0]; i < block[0] + block[1]; ++i) {
            work.compute(pending[i], nothing);
            if (stop()) break;
        }
        reports = work.flush();
    }
}

class Master {
public:
    Master(const mpi::Comm& comm, std::uint64_t entries, const TilesDone& done, const StopRequested& stop,
           std::uint64_t granule)
        : comm_(comm), entries_(entries), remaining_(entries), done_(done), stop_(stop), granule_(granule), working_(comm.size() - 1)
    {
    }

    // Answers every request already waiting.
    void serve()
    {
        int waiting = 0;
        MPI_Status st;
        for (;;) {
            mpi::check(MPI_Iprobe(MPI_ANY_SOURCE, tag_request, comm_.get(), &waiting, &st), "MPI_Iprobe");
            if (!waiting) return;
            answer(st);
        }
    }

    // Blocks until every worker has been told to stop.
    void drain()
    {
        MPI_Status st;
        while (working_ > 0) {
            mpi::check(MPI_Probe(MPI_ANY_SOURCE, tag_request, comm_.get(), &st), "MPI_Probe");
            answer(st);
        }
    }

    // Also where a stop on rank 0 is noticed.
    bool has_work()
    {
        if (!stopped_ && stop_()) stopped_ = true;
        return !stopped_ && remaining_ > 0;
    }
    // The next block: {first entry, count}.
    std::pair<std::uint64_t, std::uint64_t> take()
    {
        const std::uint64_t n = block_size(remaining_, comm_.size(), granule_);
        const std::pair<std::uint64_t, std::uint64_t> b{next_, n};
        next_ += n;
        remaining_ -= n;
        return b;
    }
    // Stopped before every tile was reported done.
    bool interrupted() const { return reported_ < entries_; }

    void record(std::span<const TileReport> reports, int rank)
    {
        reported_ += reports.size();
        done_(reports, rank);
    }

private:
    void answer(const MPI_Status& probed)
    {
        int n = 0;
        mpi::check(MPI_Get_count(&probed, MPI_UINT64_T, &n), "MPI_Get_count");
        std::vector<std::uint64_t> msg(static_cast<std::size_t>(n));
        mpi::check(MPI_Recv(msg.data(), n, MPI_UINT64_T, probed.MPI_SOURCE, tag_request, comm_.get(), MPI_STATUS_IGNORE),
                   "MPI_Recv");
        std::vector<TileReport> reports(msg[1]);
        for (std::size_t i = 0; i < reports.size(); ++i) reports[i] = {msg[2 + 2 * i], msg[3 + 2 * i]};
        if (!reports.empty()) record(reports, probed.MPI_SOURCE);
        // A rank told to stop (SIGTERM reaches every rank under Slurm) stops them all.
        if (msg[0] != 0) stopped_ = true;
        std::uint64_t block[2] = {0, 0};
        if (has_work()) {
            const auto b = take();
            block[0] = b.first;
            block[1] = b.second;
        } else {
            --working_;
        }
        mpi::check(MPI_Send(block, 2, MPI_UINT64_T, probed.MPI_SOURCE, tag_assign, comm_.get()), "MPI_Send");
    }

    const mpi::Comm& comm_;
    std::uint64_t entries_;
    std::uint64_t next_ = 0;
    std::uint64_t remaining_;
    std::uint64_t reported_ = 0;
    const TilesDone& done_;
    const StopRequested& stop_;
    std::uint64_t granule_;
    int working_;
    bool stopped_ = false;
};

}  // namespace

ScheduleResult run_schedule(const mpi::Comm& comm, std::span<const std::uint64_t> pending, TileWork& work,
                            const TilesDone& done, const StopRequested& stop, const ScheduleSettings& settings)
{
    std::int64_t interrupted = 0;
    if (comm.is_root()) {
        Master master(comm, pending.size(), done, stop, settings.granule);
        const Serve serve = comm.size() > 1 ? Serve([&master] { master.serve(); }) : Serve();
        while (master.has_work()) {
            const auto [first, count] = master.take();
            for (std::uint64_t i = first; i < first + count; ++i) {
                work.compute(pending[i], serve);
                if (serve) master.serve();
                if (stop()) break;
            }
            const std::vector<TileReport> reports = work.flush();
            if (!reports.empty()) master.record(reports, 0);
        }
        master.drain();
        interrupted = master.interrupted() ? 1 : 0;
    } else {
        worker(comm, pending, work, stop);
    }
    return {comm.broadcast(interrupted) != 0};
}

}  // namespace superball
