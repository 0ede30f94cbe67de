#include "placed_chunks.hpp"

#include "hdf5.hpp"
#include "posix_file.hpp"

#include <H5FDpublic.h>
#include <fcntl.h>
#include <fmt/core.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <system_error>

namespace superball {

struct PlacedChunks::State {
    std::uint64_t data_end = 0;
    // The undo log: the file's size, then (address, length, the bytes) of every range
    // before they are overwritten. A write that cannot be logged is not done.
    int undo = -1;
    bool log(int fd, haddr_t at, size_t size);
    // The chunk H5Dwrite_chunk is about to allocate and write, then the write to skip.
    haddr_t expect_at = HADDR_UNDEF;
    hsize_t expect_bytes = 0;
    bool allocated = false;
    bool skipped = false;
};

namespace {

// The undo log's first bytes, so that a file of that name which is not one is never taken
// for one (nor replaced: is_undo_log).
constexpr char undo_magic[8] = {'S', 'B', 'U', 'N', 'D', 'O', '0', '1'};

// Moves exactly `size` bytes at `at` with pread or pwrite (retrying short and interrupted
// calls); false on an error or at the end of the file. (The driver's callbacks report
// failure to HDF5 by their return value and cannot throw, so PosixFile's throwing calls
// do not serve here.)
template <class Byte, class Call>
bool transfer(Call call, int fd, Byte* b, std::size_t size, off_t at)
{
    while (size > 0) {
        const ssize_t n = call(fd, b, size, at);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        b += n;
        at += n;
        size -= static_cast<std::size_t>(n);
    }
    return true;
}

bool write_all(int fd, const void* data, std::size_t size, off_t at)
{
    return transfer(::pwrite, fd, static_cast<const unsigned char*>(data), size, at);
}

bool read_all(int fd, void* data, std::size_t size, off_t at)
{
    return transfer(::pread, fd, static_cast<unsigned char*>(data), size, at);
}

}  // namespace

bool PlacedChunks::State::log(int fd, haddr_t at, size_t size)
{
    // Only what exists is overwritten: bytes past the original end are cut on undo.
    if (at >= data_end) return true;
    const std::uint64_t n = std::min<std::uint64_t>(size, data_end - at);
    std::vector<unsigned char> old(n);
    if (!read_all(fd, old.data(), n, static_cast<off_t>(at))) return false;
    const std::uint64_t head[2] = {at, n};
    const off_t end = ::lseek(undo, 0, SEEK_END);  // after the header: magic, then the size
    // A process killed between these writes leaves a record cut short: applying the log
    // stops before it, and its range has not been touched yet.
    return end >= 0 && write_all(undo, old.data(), n, end + 16) && write_all(undo, head, 16, end);
}

namespace {

using State = PlacedChunks::State;

// The driver's file: HDF5's public part first, as the virtual file layer requires.
struct File {
    H5FD_t pub;
    int fd = -1;
    haddr_t eoa = 0;
    haddr_t eof = 0;
    bool writable = false;
    State* state = nullptr;
};

// What H5Pset_driver copies into a file access list: the state to share.
struct Info {
    State* state;
};

File* file_of(H5FD_t* f) { return reinterpret_cast<File*>(f); }
const File* file_of(const H5FD_t* f) { return reinterpret_cast<const File*>(f); }

void* info_get(H5FD_t* f)
{
    auto* i = static_cast<Info*>(std::malloc(sizeof(Info)));
    if (i) i->state = file_of(f)->state;
    return i;
}

void* info_copy(const void* from)
{
    auto* i = static_cast<Info*>(std::malloc(sizeof(Info)));
    if (i) std::memcpy(i, from, sizeof(Info));
    return i;
}

herr_t info_free(void* i)
{
    std::free(i);
    return 0;
}

H5FD_t* open_file(const char* name, unsigned flags, hid_t fapl, haddr_t)
{
    const Info* info = static_cast<const Info*>(H5Pget_driver_info(fapl));
    if (!info || !info->state) return nullptr;
    int o = (flags & H5F_ACC_RDWR) ? O_RDWR : O_RDONLY;
    if (flags & H5F_ACC_CREAT) o |= O_CREAT;
    const int fd = ::open(name, o | O_CLOEXEC, 0666);
    if (fd < 0) return nullptr;
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        ::close(fd);
        return nullptr;
    }
    // Zeroed like the C drivers' structures: HDF5 fills in the public part.
    auto* f = static_cast<File*>(std::calloc(1, sizeof(File)));
    if (!f) {
        ::close(fd);
        return nullptr;
    }
    f->fd = fd;
    f->eof = static_cast<haddr_t>(st.st_size);
    f->writable = (flags & H5F_ACC_RDWR) != 0;
    f->state = info->state;
    return &f->pub;
}

herr_t close_file(H5FD_t* h)
{
    File* f = file_of(h);
    const int r = ::close(f->fd);
    std::free(f);
    return r == 0 ? 0 : -1;
}

herr_t query(const H5FD_t*, unsigned long* flags)
{
    // Small metadata writes gathered into larger ones. No aggregation of allocations: each
    // one must come to alloc() below, which places the chunks.
    *flags = H5FD_FEAT_ACCUMULATE_METADATA;
    return 0;
}

// Past the kept bytes at least.
void keep_data(File* f)
{
    if (f->eoa < f->state->data_end) f->eoa = f->state->data_end;
}

haddr_t allocate(H5FD_t* h, H5FD_mem_t type, hid_t, hsize_t size)
{
    File* f = file_of(h);
    State& s = *f->state;
    if (type == H5FD_MEM_DRAW && s.expect_at != HADDR_UNDEF && !s.allocated) {
        if (size != s.expect_bytes) return HADDR_UNDEF;  // not the chunk announced: add() reports it
        s.allocated = true;
        return s.expect_at;
    }
    keep_data(f);
    const haddr_t at = f->eoa;
    f->eoa += size;
    return at;
}

haddr_t get_eoa(const H5FD_t* h, H5FD_mem_t) { return file_of(h)->eoa; }

herr_t set_eoa(H5FD_t* h, H5FD_mem_t, haddr_t at)
{
    File* f = file_of(h);
    f->eoa = at;
    keep_data(f);
    return 0;
}

haddr_t get_eof(const H5FD_t* h, H5FD_mem_t) { return file_of(h)->eof; }

herr_t read_at(H5FD_t* h, H5FD_mem_t, hid_t, haddr_t at, size_t size, void* buffer)
{
    const File* f = file_of(h);
    auto* b = static_cast<unsigned char*>(buffer);
    while (size > 0) {
        const ssize_t n = ::pread(f->fd, b, size, static_cast<off_t>(at));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return -1;
        if (n == 0) {  // past the end of the file: zeros, as HDF5's own drivers read
            std::memset(b, 0, size);
            return 0;
        }
        b += n;
        at += static_cast<haddr_t>(n);
        size -= static_cast<size_t>(n);
    }
    return 0;
}

herr_t write_at(H5FD_t* h, H5FD_mem_t type, hid_t, haddr_t at, size_t size, const void* buffer)
{
    File* f = file_of(h);
    State& s = *f->state;
    if (type == H5FD_MEM_DRAW && s.expect_at != HADDR_UNDEF) {
        // Inside add(): the only raw write is the chunk's, whose bytes are there already
        // (and whose buffer is a placeholder: nothing else may be written from it).
        if (!s.allocated || s.skipped || at != s.expect_at || size != s.expect_bytes) return -1;
        s.skipped = true;
        return 0;
    }
    if (!s.log(f->fd, at, size)) return -1;
    if (!write_all(f->fd, buffer, size, static_cast<off_t>(at))) return -1;
    if (at + size > f->eof) f->eof = at + size;
    return 0;
}

// HDF5 makes the file end at its end of allocation; this driver never cuts it shorter:
// bytes past HDF5's end are chunks (HDF5's own drivers would cut them away), and rank 0 may
// be appending more while the file is open here.
herr_t truncate(H5FD_t* h, hid_t, hbool_t)
{
    File* f = file_of(h);
    if (!f->writable || f->eof >= f->eoa) return 0;
    if (::ftruncate(f->fd, static_cast<off_t>(f->eoa)) != 0) return -1;
    f->eof = f->eoa;
    return 0;
}

// The driver, registered with HDF5 once per process (HDF5's driver table is itself
// global; the registration is never undone, as for HDF5's own drivers).
hid_t driver()
{
    static const H5FD_class_t cls = {
        "superball_placed",
        static_cast<haddr_t>(std::numeric_limits<off_t>::max()),
        H5F_CLOSE_WEAK,
        nullptr,  // terminate
        nullptr,  // sb_size
        nullptr,  // sb_encode
        nullptr,  // sb_decode
        sizeof(Info),
        info_get,
        info_copy,
        info_free,
        0,        // dxpl_size
        nullptr,  // dxpl_copy
        nullptr,  // dxpl_free
        open_file,
        close_file,
        nullptr,  // cmp
        query,
        nullptr,  // get_type_map
        allocate,
        nullptr,  // free
        get_eoa,
        set_eoa,
        get_eof,
        nullptr,  // get_handle
        read_at,
        write_at,
        nullptr,  // flush
        truncate,
        nullptr,  // lock
        nullptr,  // unlock
        H5FD_FLMAP_DICHOTOMY,
    };
    static const hid_t id = h5::check(H5FDregister(&cls), "H5FDregister");
    return id;
}

}  // namespace

PlacedChunks::PlacedChunks(const std::filesystem::path& path) : state_(std::make_unique<State>())
{
    state_->data_end = std::filesystem::file_size(path);
    // The log's header (magic, then the file's size) is written under another name and the
    // log renamed into place: a run killed before the rename leaves no log, one killed after
    // leaves a whole header. (Written in place, a run killed between its two writes left a
    // log with the magic alone, which the next run could neither apply nor ignore.)
    const std::filesystem::path undo = undo_path(path);
    const std::filesystem::path fresh = unfinished_undo_path(path);
    state_->undo = ::open(fresh.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (state_->undo < 0) throw h5::Error("cannot create " + fresh.string() + ": " + std::strerror(errno));
    char header[sizeof undo_magic + 8];
    const std::uint64_t size = state_->data_end;
    std::memcpy(header, undo_magic, sizeof undo_magic);
    std::memcpy(header + sizeof undo_magic, &size, 8);
    if (!write_all(state_->undo, header, sizeof header, 0) || ::rename(fresh.c_str(), undo.c_str()) != 0) {
        const std::string why = std::strerror(errno);
        ::close(state_->undo);
        // Nothing of the file has changed yet: the log, unfinished, would only stand in the
        // way of a resume (it is not an undo log a resume can read).
        ::unlink(fresh.c_str());
        throw h5::Error("cannot write " + undo.string() + ": " + why);
    }
    const h5::Id fapl = h5::file_access(0);
    const Info info{state_.get()};
    h5::check(H5Pset_driver(fapl, driver(), &info), "H5Pset_driver");
    file_ = h5::open_file(path, true, fapl);
}

PlacedChunks::~PlacedChunks()
{
    file_ = h5::Id();  // closed before the log it writes to
    if (state_->undo >= 0) ::close(state_->undo);
}

std::filesystem::path PlacedChunks::unfinished_undo_path(const std::filesystem::path& path)
{
    std::filesystem::path p = undo_path(path);
    p += ".new";
    return p;
}

std::filesystem::path PlacedChunks::undo_path(const std::filesystem::path& path)
{
    std::filesystem::path p = path;
    p += ".undo";
    return p;
}

bool PlacedChunks::is_undo_log(const std::filesystem::path& path)
{
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    char magic[sizeof undo_magic] = {};
    const bool ok = read_all(fd, magic, sizeof magic, 0) && std::memcmp(magic, undo_magic, sizeof magic) == 0;
    ::close(fd);
    return ok;
}

void PlacedChunks::discard_undo(const std::filesystem::path& path)
{
    std::error_code ec;
    std::filesystem::remove(undo_path(path), ec);
    std::filesystem::remove(unfinished_undo_path(path), ec);
}

bool PlacedChunks::undo_interrupted_changes(const std::filesystem::path& path)
{
    const std::filesystem::path undo = undo_path(path);
    std::error_code ec;
    if (!std::filesystem::exists(undo, ec)) return false;
    const auto fail = [&](const std::string& why) {
        return std::runtime_error(fmt::format("{} was being finished when the run stopped, and its undo log {} cannot be applied "
                                              "({})",
                                              path.string(), undo.string(), why));
    };
    const int log = ::open(undo.c_str(), O_RDONLY | O_CLOEXEC);
    if (log < 0) throw fail(std::strerror(errno));
    const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
        const int e = errno;
        ::close(log);
        throw fail(std::string("opening the file: ") + std::strerror(e));
    }
    std::uint64_t size = 0;
    char magic[sizeof undo_magic] = {};
    if (!read_all(log, magic, sizeof magic, 0) || std::memcmp(magic, undo_magic, sizeof magic) != 0) {
        ::close(fd);
        ::close(log);
        throw fail("it does not start as an undo log");
    }
    if (!read_all(log, &size, 8, sizeof undo_magic)) {
        // The header cut short (a run killed while writing it in place, as superball did
        // before the rename): it is written before the file is touched, so nothing changed.
        ::close(fd);
        ::close(log);
        std::filesystem::remove(undo, ec);
        return false;
    }
    bool ok = true;
    off_t at = sizeof undo_magic + 8;
    // Records in the order written (a record cut short ends the log), applied last first:
    // a range written twice (the superblock, at open and at close) gets its first bytes.
    struct Record {
        std::uint64_t at;
        std::vector<unsigned char> bytes;
    };
    std::vector<Record> records;
    std::uint64_t head[2] = {};
    while (ok && read_all(log, head, 16, at)) {
        Record r{head[0], std::vector<unsigned char>(head[1])};
        if (head[0] + head[1] > size || !read_all(log, r.bytes.data(), r.bytes.size(), at + 16)) break;
        at += static_cast<off_t>(16 + head[1]);
        records.push_back(std::move(r));
    }
    for (auto r = records.rbegin(); ok && r != records.rend(); ++r) {
        ok = write_all(fd, r->bytes.data(), r->bytes.size(), static_cast<off_t>(r->at));
    }
    ok = ok && ::ftruncate(fd, static_cast<off_t>(size)) == 0 && ::fsync(fd) == 0;
    const int e = errno;
    ::close(fd);
    ::close(log);
    if (!ok) throw fail(std::strerror(e));
    std::filesystem::remove(undo, ec);
    return true;
}

void PlacedChunks::add(hid_t dataset, const std::vector<hsize_t>& origin, std::uint64_t address, std::uint64_t bytes)
{
    State& s = *state_;
    s.expect_at = address;
    s.expect_bytes = bytes;
    s.allocated = s.skipped = false;
    // HDF5 reads nothing from the buffer once the write is skipped; it must not be null.
    const unsigned char unused = 0;
    const herr_t r = H5Dwrite_chunk(dataset, H5P_DEFAULT, 0, origin.data(), bytes, &unused);
    const bool placed = s.allocated && s.skipped;
    s.expect_at = HADDR_UNDEF;
    // The message only when it fails: this runs once a chunk, a million times in a large run.
    if (r < 0) h5::check(r, fmt::format("indexing the chunk of {} bytes at byte {}", bytes, address));
    if (!placed) {
        throw h5::Error(fmt::format("HDF5 did not index the chunk of {} bytes at byte {} where it lies", bytes, address));
    }
}

void PlacedChunks::close() { file_.close(); }

void PlacedChunks::cover(const std::filesystem::path& path)
{
    // A checkpoint: the file full at this moment rather than while tiles are appended says
    // what the appender's failures say (partial_file.cpp).
    try {
        PlacedChunks file(path);
        file.close();
    } catch (const std::exception& e) {
        throw h5::Error(fmt::format("writing the checkpoint of {} failed ({}){}; {}", path.string(), e.what(),
                                    free_space_note(path), resume_after_failure));
    }
    discard_undo(path);
}

}  // namespace superball
