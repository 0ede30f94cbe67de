#include "schedule.hpp"

namespace superball {

namespace {

constexpr int tag_request = 1;  // worker -> 0: {tile it finished or -1, 1 if it was told to stop}
constexpr int tag_assign = 2;   // 0 -> worker: the next tile, or -1: no more

void worker(const mpi::Comm& comm, const TileWork& work, const StopRequested& stop)
{
    const Serve nothing = [] {};
    std::int64_t finished = -1;
    for (;;) {
        const std::int64_t request[2] = {finished, stop() ? 1 : 0};
        mpi::check(MPI_Send(request, 2, MPI_INT64_T, 0, tag_request, comm.get()), "MPI_Send");
        std::int64_t tile = -1;
        mpi::check(MPI_Recv(&tile, 1, MPI_INT64_T, 0, tag_assign, comm.get(), MPI_STATUS_IGNORE), "MPI_Recv");
        if (tile < 0) return;
        work(static_cast<std::uint64_t>(tile), nothing);
        finished = tile;
    }
}

class Master {
public:
    Master(const mpi::Comm& comm, std::deque<std::uint64_t> pending, const TileDone& done, const StopRequested& stop)
        : comm_(comm), pending_(std::move(pending)), done_(done), stop_(stop), working_(comm.size() - 1)
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
            answer(st.MPI_SOURCE);
        }
    }

    // Blocks until every worker has been told to stop.
    void drain()
    {
        while (working_ > 0) answer(MPI_ANY_SOURCE);
    }

    // Also where a stop on rank 0 is noticed.
    bool has_work()
    {
        if (!stopped_ && stop_()) stopped_ = true;
        return !stopped_ && !pending_.empty();
    }
    std::uint64_t take()
    {
        const std::uint64_t t = pending_.front();
        pending_.pop_front();
        return t;
    }
    bool interrupted() const { return stopped_ && !pending_.empty(); }

private:
    void answer(int source)
    {
        std::int64_t request[2] = {-1, 0};
        MPI_Status st;
        mpi::check(MPI_Recv(request, 2, MPI_INT64_T, source, tag_request, comm_.get(), &st), "MPI_Recv");
        if (request[0] >= 0) done_(static_cast<std::uint64_t>(request[0]), st.MPI_SOURCE);
        // A rank told to stop (SIGTERM reaches every rank under Slurm) stops them all.
        if (request[1] != 0) stopped_ = true;
        const std::int64_t next = has_work() ? static_cast<std::int64_t>(take()) : -1;
        if (next < 0) --working_;
        mpi::check(MPI_Send(&next, 1, MPI_INT64_T, st.MPI_SOURCE, tag_assign, comm_.get()), "MPI_Send");
    }

    const mpi::Comm& comm_;
    std::deque<std::uint64_t> pending_;
    const TileDone& done_;
    const StopRequested& stop_;
    int working_;
    bool stopped_ = false;
};

}  // namespace

ScheduleResult run_schedule(const mpi::Comm& comm, std::deque<std::uint64_t> pending, const TileWork& work,
                            const TileDone& done, const StopRequested& stop)
{
    std::int64_t interrupted = 0;
    if (comm.is_root()) {
        Master master(comm, std::move(pending), done, stop);
        const Serve serve = [&master] { master.serve(); };
        while (master.has_work()) {
            const std::uint64_t t = master.take();
            work(t, serve);
            done(t, 0);
            master.serve();
        }
        master.drain();
        interrupted = master.interrupted() ? 1 : 0;
    } else {
        worker(comm, work, stop);
    }
    return {comm.broadcast(interrupted) != 0};
}

}  // namespace superball
