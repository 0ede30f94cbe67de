#include "mpi.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace superball::mpi {

namespace {

bool is_set(const Getenv& getenv, const char* name) { return getenv(name) != nullptr; }

// Whether an MCA parameter file sets `key` (lines `key = value`, `#` comments).
bool sets_key(std::string_view params, std::string_view key)
{
    std::istringstream in{std::string(params)};
    for (std::string line; std::getline(in, line);) {
        if (const auto comment = line.find('#'); comment != std::string::npos) line.resize(comment);
        const auto eq = line.find('=');
        if (eq == std::string::npos) continue;
        std::string_view name(line.data(), eq);
        while (!name.empty() && (name.front() == ' ' || name.front() == '\t')) name.remove_prefix(1);
        while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.remove_suffix(1);
        if (name == key) return true;
    }
    return false;
}

#ifdef OPEN_MPI  // only Open MPI reads it (SMPI, tests/scale, is another MPI)
std::string user_mca_params(const Getenv& getenv)
{
    const char* home = getenv("HOME");
    if (home == nullptr) return {};
    std::ifstream in(std::string(home) + "/.openmpi/mca-params.conf");
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}
#endif

}  // namespace

std::vector<McaSetting> single_node_mca(const Getenv& getenv, std::string_view user_params)
{
    if (is_set(getenv, "OMPI_MCA_mca_base_param_files")) return {};
    bool singleton = true;
    if (const char* size = getenv("OMPI_COMM_WORLD_SIZE")) {
        const char* local = getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
        if (local == nullptr || std::string_view(local) != size) return {};
        singleton = false;
    } else {
        for (const char* launcher : {"PMIX_RANK", "PMI_RANK", "PMI_SIZE", "PMI_FD"}) {
            if (is_set(getenv, launcher)) return {};
        }
    }
    // Each setting with the parameters whose value, set by the user, means it is left alone.
    struct Wanted {
        McaSetting setting;
        std::vector<std::string> unless;
    };
    std::vector<Wanted> wanted{{{"pml", "ob1"}, {"pml"}}};
    if (singleton) wanted.push_back({{"ess_singleton_isolated", "1"}, {"ess_singleton_isolated"}});
    std::vector<McaSetting> settings;
    for (Wanted& w : wanted) {
        const bool users = std::any_of(w.unless.begin(), w.unless.end(), [&](const std::string& name) {
            return is_set(getenv, ("OMPI_MCA_" + name).c_str()) || sets_key(user_params, name);
        });
        if (!users) settings.push_back(std::move(w.setting));
    }
    return settings;
}

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
#ifdef OPEN_MPI
    const Getenv getenv = [](const char* name) { return std::getenv(name); };
    for (const McaSetting& s : single_node_mca(getenv, user_mca_params(getenv))) {
        // Never replaces a value (the last argument): single_node_mca() checked there is none.
        ::setenv(("OMPI_MCA_" + s.name).c_str(), s.value.c_str(), 0);
        if (s.name == "ess_singleton_isolated" && !is_set(getenv, "OMPI_MCA_orte_tmpdir_base")) {
            const char* tmp = getenv("TMPDIR");
            std::string dir = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/superball-mpi-XXXXXX";
            // Without it the process still runs, sharing the directory as before.
            if (::mkdtemp(dir.data()) != nullptr) {
                ::setenv("OMPI_MCA_orte_tmpdir_base", dir.c_str(), 1);
                session_base_.emplace(std::move(dir));
            }
        }
    }
#endif
    // The command-line arguments are not MPI's business. FUNNELED: the run's writer threads
    // (io/posix_file.hpp) make no MPI call, only the main thread does.
    int provided = MPI_THREAD_SINGLE;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    if (provided < MPI_THREAD_FUNNELED) {
        MPI_Finalize();
        throw std::runtime_error("MPI_Init_thread: this MPI library cannot run a process with threads (MPI_THREAD_FUNNELED)");
    }
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
}

#ifdef OPEN_MPI
namespace {

// Turns Nagle's algorithm off on this process's TCP connections to its own host. Open MPI
// 4.1's PMIx client reaches the local server (mpirun or orted) over loopback TCP without
// TCP_NODELAY, and MPI_Finalize sends it four small messages in a row: the later ones wait
// for the acknowledgement of the first, which the server delays by Linux's 40 ms. Every
// run under mpirun spent 45 ms in MPI_Finalize here, a third of a small job's time; with
// this, 3 ms (a minimal MPI program under `mpirun -n 2`: 0.10 s in all against 0.06). Only
// the option changes, never a byte of what is sent, and only on connections to this host;
// the file descriptors are the process's own (no library state is touched).
void no_delay_on_loopback()
{
    for (int fd = 0; fd < 1024; ++fd) {
        int type = 0;
        socklen_t size = sizeof type;
        if (::getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &size) != 0 || type != SOCK_STREAM) continue;
        sockaddr_storage peer{};
        socklen_t peer_size = sizeof peer;
        if (::getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &peer_size) != 0) continue;
        bool loopback = false;
        if (peer.ss_family == AF_INET) {
            loopback = (ntohl(reinterpret_cast<const sockaddr_in&>(peer).sin_addr.s_addr) >> 24) == 127;
        } else if (peer.ss_family == AF_INET6) {
            loopback = IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<const sockaddr_in6&>(peer).sin6_addr);
        }
        const int one = 1;
        if (loopback) ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
}

}  // namespace
#endif

Environment::~Environment()
{
#ifdef OPEN_MPI
    no_delay_on_loopback();
#endif
    MPI_Finalize();
}

Environment::PrivateDirectory::~PrivateDirectory()
{
    std::error_code ignored;  // a directory left in /tmp is no reason to fail a finished run
    std::filesystem::remove_all(path_, ignored);
}


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

void Comm::broadcast(std::vector<double>& v) const
{
    auto n = static_cast<std::uint64_t>(v.size());
    check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm_), "MPI_Bcast");
    v.resize(n);
    check(MPI_Bcast(v.data(), static_cast<int>(n), MPI_DOUBLE, 0, comm_), "MPI_Bcast");
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

std::vector<std::int32_t> Comm::max(const std::vector<std::int32_t>& v) const
{
    std::vector<std::int32_t> out(v.size());
    check(MPI_Allreduce(v.data(), out.data(), static_cast<int>(v.size()), MPI_INT32_T, MPI_MAX, comm_), "MPI_Allreduce");
    return out;
}

void Comm::send(const std::vector<std::uint64_t>& v, int to, int tag) const
{
    check(MPI_Send(v.data(), static_cast<int>(v.size()), MPI_UINT64_T, to, tag, comm_), "MPI_Send");
}

std::vector<std::uint64_t> Comm::receive(std::size_t n, int from, int tag) const
{
    std::vector<std::uint64_t> v(n);
    check(MPI_Recv(v.data(), static_cast<int>(n), MPI_UINT64_T, from, tag, comm_, MPI_STATUS_IGNORE), "MPI_Recv");
    return v;
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

OwnedComm OwnedComm::range(const Comm& c, int first, int last, int stride, int tag)
{
    // The two groups are freed here whatever happens: a group owns nothing the new
    // communicator needs (MPI-3.1, 6.3.2), and these are their only uses.
    struct Group {
        MPI_Group g = MPI_GROUP_NULL;
        ~Group()
        {
            if (g != MPI_GROUP_NULL) MPI_Group_free(&g);
        }
    };
    Group all;
    check(MPI_Comm_group(c.get(), &all.g), "MPI_Comm_group");
    int triple[1][3] = {{first, last, stride}};
    Group part;
    check(MPI_Group_range_incl(all.g, 1, triple, &part.g), "MPI_Group_range_incl");
    MPI_Comm out = MPI_COMM_NULL;
    check(MPI_Comm_create_group(c.get(), part.g, tag, &out), "MPI_Comm_create_group");
    return OwnedComm(out);
}

OwnedComm OwnedComm::dup(const Comm& c)
{
    MPI_Comm out = MPI_COMM_NULL;
    check(MPI_Comm_dup(c.get(), &out), "MPI_Comm_dup");
    return OwnedComm(out);
}

int host_count(const Comm& c)
{
    const OwnedComm node = OwnedComm::split_shared(c, c.rank());
    const std::uint64_t first_of_node = node.view().rank() == 0 ? 1 : 0;
    return static_cast<int>(c.sum({first_of_node}).front());
}

}  // namespace superball::mpi
