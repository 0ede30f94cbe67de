#include "mpi.hpp"

namespace superball::mpi {

void check(int code, const char* what)
{
    if (code == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(code, text, &len);
    throw std::runtime_error(std::string(what) + ": " + std::string(text, static_cast<std::size_t>(len)));
}

Environment::Environment()
{
    // Only `explore` starts MPI, so the command-line arguments are not MPI's business.
    check(MPI_Init(nullptr, nullptr), "MPI_Init");
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
}

Environment::~Environment() { MPI_Finalize(); }

int Comm::rank() const
{
    int r = 0;
    check(MPI_Comm_rank(comm_, &r), "MPI_Comm_rank");
    return r;
}

int Comm::size() const
{
    int s = 0;
    check(MPI_Comm_size(comm_, &s), "MPI_Comm_size");
    return s;
}

void Comm::barrier() const { check(MPI_Barrier(comm_), "MPI_Barrier"); }

void Comm::broadcast(std::string& s) const
{
    auto n = static_cast<std::uint64_t>(s.size());
    check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm_), "MPI_Bcast");
    s.resize(n);
    check(MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, comm_), "MPI_Bcast");
}

void Comm::broadcast(std::vector<std::uint64_t>& v) const
{
    auto n = static_cast<std::uint64_t>(v.size());
    check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm_), "MPI_Bcast");
    v.resize(n);
    check(MPI_Bcast(v.data(), static_cast<int>(n), MPI_UINT64_T, 0, comm_), "MPI_Bcast");
}

std::int64_t Comm::broadcast(std::int64_t x) const
{
    check(MPI_Bcast(&x, 1, MPI_INT64_T, 0, comm_), "MPI_Bcast");
    return x;
}

std::vector<std::uint64_t> Comm::sum(const std::vector<std::uint64_t>& v) const
{
    std::vector<std::uint64_t> out(v.size());
    check(MPI_Allreduce(v.data(), out.data(), static_cast<int>(v.size()), MPI_UINT64_T, MPI_SUM, comm_),
          "MPI_Allreduce");
    return out;
}

double Comm::max(double x) const
{
    double out = 0;
    check(MPI_Allreduce(&x, &out, 1, MPI_DOUBLE, MPI_MAX, comm_), "MPI_Allreduce");
    return out;
}

std::vector<double> Comm::gather(const std::vector<double>& mine) const
{
    const int n = static_cast<int>(mine.size());
    std::vector<int> counts(is_root() ? static_cast<std::size_t>(size()) : 0);
    check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_), "MPI_Gather");
    std::vector<int> offsets(counts.size());
    std::vector<double> all;
    if (is_root()) {
        int total = 0;
        for (std::size_t r = 0; r < counts.size(); ++r) {
            offsets[r] = total;
            total += counts[r];
        }
        all.resize(static_cast<std::size_t>(total));
    }
    check(MPI_Gatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, comm_),
          "MPI_Gatherv");
    return all;
}

double Comm::broadcast(double x) const
{
    check(MPI_Bcast(&x, 1, MPI_DOUBLE, 0, comm_), "MPI_Bcast");
    return x;
}

void Comm::abort(int status) const
{
    MPI_Abort(comm_, status);
    std::abort();
}

OwnedComm::~OwnedComm()
{
    if (comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

OwnedComm& OwnedComm::operator=(OwnedComm&& o) noexcept
{
    if (this != &o) {
        if (comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
        comm_ = o.comm_;
        o.comm_ = MPI_COMM_NULL;
    }
    return *this;
}

OwnedComm OwnedComm::split(const Comm& c, int color, int key)
{
    MPI_Comm out = MPI_COMM_NULL;
    check(MPI_Comm_split(c.get(), color, key, &out), "MPI_Comm_split");
    return OwnedComm(out);
}

OwnedComm OwnedComm::split_shared(const Comm& c, int key)
{
    MPI_Comm out = MPI_COMM_NULL;
    check(MPI_Comm_split_type(c.get(), MPI_COMM_TYPE_SHARED, key, MPI_INFO_NULL, &out), "MPI_Comm_split_type");
    return OwnedComm(out);
}

OwnedComm OwnedComm::dup(const Comm& c)
{
    MPI_Comm out = MPI_COMM_NULL;
    check(MPI_Comm_dup(c.get(), &out), "MPI_Comm_dup");
    return OwnedComm(out);
}

}  // namespace superball::mpi
