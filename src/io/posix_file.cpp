#include "posix_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <utility>

namespace superball {

namespace {
[[noreturn]] void fail(const char* what)
{
    throw std::system_error(errno, std::generic_category(), what);
}
}  // namespace

PosixFile::PosixFile(const std::filesystem::path& path, bool writable)
    : fd_(::open(path.c_str(), (writable ? O_RDWR : O_RDONLY) | O_CLOEXEC))
{
    if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "open " + path.string());
}

PosixFile::~PosixFile()
{
    if (fd_ >= 0) ::close(fd_);
}

PosixFile::PosixFile(PosixFile&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}

void PosixFile::write_at(std::uint64_t offset, const void* data, std::size_t bytes) const
{
    const auto* p = static_cast<const char*>(data);
    while (bytes > 0) {
        const ssize_t n = ::pwrite(fd_, p, bytes, static_cast<off_t>(offset));
        if (n < 0) {
            if (errno == EINTR) continue;
            fail("write");
        }
        if (n == 0) {
            errno = ENOSPC;  // a regular file that takes nothing more: no room
            fail("write");
        }
        p += n;
        offset += static_cast<std::uint64_t>(n);
        bytes -= static_cast<std::size_t>(n);
    }
}

void PosixFile::sync_data() const
{
    while (::fdatasync(fd_) != 0) {
        if (errno != EINTR) fail("fdatasync");
    }
}

std::uint64_t PosixFile::size() const
{
    struct stat st {};
    if (::fstat(fd_, &st) != 0) fail("stat");
    return static_cast<std::uint64_t>(st.st_size);
}

void PosixFile::read_at(std::uint64_t offset, void* data, std::size_t bytes) const
{
    auto* p = static_cast<char*>(data);
    while (bytes > 0) {
        const ssize_t n = ::pread(fd_, p, bytes, static_cast<off_t>(offset));
        if (n < 0) {
            if (errno == EINTR) continue;
            fail("read");
        }
        if (n == 0) throw std::runtime_error("read: the file ends before the data it should hold (truncated)");
        p += n;
        offset += static_cast<std::uint64_t>(n);
        bytes -= static_cast<std::size_t>(n);
    }
}

void PosixFile::close()
{
    if (fd_ >= 0 && ::close(std::exchange(fd_, -1)) != 0) fail("close");
}

std::string free_space_note(const std::filesystem::path& path)
{
    struct statvfs fs{};
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    if (statvfs(dir.c_str(), &fs) != 0) return "";
    if (fs.f_flag & ST_RDONLY) return "; the file system holding it is read-only";
    const auto free_bytes = static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize;
    if (free_bytes >= (1ull << 20)) return "";
    return "; the file system holding it is full (" + std::to_string(free_bytes) + " bytes free)";
}

}  // namespace superball
