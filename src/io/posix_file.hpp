// A file opened with POSIX open(2): RAII around the descriptor, whole transfers at byte
// offsets. The partial file's tiles are written this way, each rank on its own
// descriptor, from a thread of the rank's own (TileWriter) that makes no MPI call: Open
// MPI 4.1's nonblocking MPI-IO requests crash in MPI_Wait when a write fails (a full disk;
// open-mpi/ompi#4807, #6078), and blocking MPI-IO writes could not overlap with counting.
// Parallel file systems (Lustre, GPFS) give POSIX semantics to writes of disjoint ranges
// from many clients.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace superball {

class PosixFile {
public:
    // Opens an existing file for reading and writing (or reading only); std::system_error
    // naming it if not.
    explicit PosixFile(const std::filesystem::path& path, bool writable = true);
    ~PosixFile();
    PosixFile(PosixFile&& o) noexcept;
    PosixFile& operator=(PosixFile&&) = delete;
    PosixFile(const PosixFile&) = delete;
    PosixFile& operator=(const PosixFile&) = delete;

    // Writes or reads exactly `bytes` bytes at `offset` (retrying short transfers and
    // interrupted calls); std::system_error on failure (ENOSPC for a full disk).
    void write_at(std::uint64_t offset, const void* data, std::size_t bytes) const;
    void read_at(std::uint64_t offset, void* data, std::size_t bytes) const;
    // The file's data written so far on stable storage (fdatasync): what a node's crash
    // cannot take back. std::system_error on failure.
    void sync_data() const;
    // The file's size in bytes.
    std::uint64_t size() const;
    // Closes now, reporting failure (the destructor cannot).
    void close();

private:
    int fd_ = -1;
};

// Why a write to `path` may have failed, when its file system can tell: "" or "; the file
// system holding it is full (N bytes free)" or "...is read-only".
std::string free_space_note(const std::filesystem::path& path);

// What a failed write of the partial file leaves, said after the failure.
inline constexpr const char* resume_after_failure =
    "the tiles recorded done are kept: run the same command with --resume once the cause is fixed";

}  // namespace superball
