// Many writers into one file, the two ways a writer could write its granted file space
// (docs/decisions.md, "Many writers write with POSIX calls"): every rank a writer, writing
// PER_RANK MiB in 8 MiB writes (ChunkAppender's buffer) at offsets granted round-robin, with
//   posix:      pwrite + fdatasync after each write, on a descriptor of the rank's own
//               (superball's way: a writer's tiles are durable before they are reported);
//   posix-once: pwrite, one fdatasync at the end;
//   mpiio-once: MPI_File_write_at (independent) on a file every rank opened collectively
//               (MPI_File_open), one MPI_File_sync at the end (it is collective: MPI-IO has
//               no way for one writer alone to make its writes durable),
// in turn, REPS times each; prints each repetition's wall time (the slowest rank, from a
// barrier to the last write durable) and the medians, GB/s of the whole.
//
//   mpirun -n 4 --oversubscribe build/release/tests/bench/bench_writers DIR [PER_RANK_MIB=256] [REPS=5]
#include <fcntl.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

constexpr std::size_t write_bytes = std::size_t{8} << 20;

// The offsets of a rank's writes: 8 stripes granted at a time, the grants round-robin over
// the ranks (as rank 0 would grant writers asking at the same pace).
std::size_t offset(int rank, int ranks, std::size_t write) { return (write * ranks + rank) * write_bytes; }

double posix(const std::string& path, int rank, int ranks, std::size_t writes, const std::vector<char>& data, bool each)
{
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT, 0644);
    if (fd < 0) throw std::runtime_error("open " + path);
    MPI_Barrier(MPI_COMM_WORLD);
    const double start = MPI_Wtime();
    for (std::size_t w = 0; w < writes; ++w) {
        if (::pwrite(fd, data.data(), write_bytes, static_cast<off_t>(offset(rank, ranks, w))) !=
                static_cast<ssize_t>(write_bytes) ||
            (each && ::fdatasync(fd) != 0)) {
            throw std::runtime_error("pwrite");
        }
    }
    if (!each && ::fdatasync(fd) != 0) throw std::runtime_error("fdatasync");
    const double seconds = MPI_Wtime() - start;
    ::close(fd);
    return seconds;
}

double mpiio(const std::string& path, int rank, int ranks, std::size_t writes, const std::vector<char>& data)
{
    MPI_File f;
    if (MPI_File_open(MPI_COMM_WORLD, path.c_str(), MPI_MODE_WRONLY | MPI_MODE_CREATE, MPI_INFO_NULL, &f) != MPI_SUCCESS) {
        throw std::runtime_error("MPI_File_open " + path);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    const double start = MPI_Wtime();
    for (std::size_t w = 0; w < writes; ++w) {
        MPI_Status st;
        if (MPI_File_write_at(f, static_cast<MPI_Offset>(offset(rank, ranks, w)), data.data(), static_cast<int>(write_bytes),
                              MPI_BYTE, &st) != MPI_SUCCESS) {
            throw std::runtime_error("MPI_File_write_at");
        }
    }
    // MPI_File_sync is collective: every rank's writes durable, as the fdatasync of each.
    MPI_File_sync(f);
    const double seconds = MPI_Wtime() - start;
    MPI_File_close(&f);
    return seconds;
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv)
{
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    if (argc < 2) {
        if (rank == 0) std::fprintf(stderr, "usage: bench_writers DIR [PER_RANK_MIB] [REPS]\n");
        MPI_Finalize();
        return 2;
    }
    const std::string dir = argv[1];
    const std::size_t per_rank = (argc > 2 ? std::stoul(argv[2]) : 256) << 20;
    const int reps = argc > 3 ? std::stoi(argv[3]) : 5;
    const std::size_t writes = per_rank / write_bytes;
    std::vector<char> data(write_bytes, static_cast<char>(rank + 1));
    const char* names[3] = {"posix", "posix-once", "mpiio-once"};
    std::vector<double> times[3];
    for (int r = 0; r < reps; ++r) {
        for (int way = 0; way < 3; ++way) {
            const std::string path = dir + "/bench_writers." + std::to_string(way);
            if (rank == 0) ::unlink(path.c_str());
            MPI_Barrier(MPI_COMM_WORLD);
            const double mine = way < 2 ? posix(path, rank, ranks, writes, data, way == 0) : mpiio(path, rank, ranks, writes, data);
            double slowest = 0;
            MPI_Reduce(&mine, &slowest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
            times[way].push_back(slowest);
            if (rank == 0) {
                std::printf("repetition %d %s: %.3f s\n", r + 1, names[way], slowest);
                ::unlink(path.c_str());
            }
        }
    }
    if (rank == 0) {
        const double bytes = static_cast<double>(writes * write_bytes) * ranks;
        std::printf("%d writers, %zu MiB each, medians of %d:", ranks, per_rank >> 20, reps);
        for (int way = 0; way < 3; ++way) {
            std::printf(" %s %.3f s (%.2f GB/s)", names[way], median(times[way]), bytes / median(times[way]) / 1e9);
        }
        std::printf("\n");
    }
    MPI_Finalize();
    return 0;
}
