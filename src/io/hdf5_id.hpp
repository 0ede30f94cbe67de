// HDF5 identifiers owned (RAII) and HDF5's failures as typed errors, without HDF5's own
// headers: with parallel HDF5 those include mpi.h, and a reader of results (info, analyse,
// serve, the Python module) includes this, not MPI. hid_t and herr_t are declared as
// HDF5 1.10 declares them (hdf5.hpp checks that they agree).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

typedef std::int64_t hid_t;  // NOLINT(modernize-use-using): the same declaration as H5Ipublic.h
typedef int herr_t;          // NOLINT(modernize-use-using): the same declaration as H5public.h

namespace superball::h5 {

// An HDF5 call failed (I/O, a damaged file, the library).
struct Error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The innermost message of HDF5's error stack for the last failed call (the stack is
// silenced, not printed), e.g. "truncated file: eof = ..."; "" if there is none.
std::string error_detail();

// Throws Error(what) when an HDF5 call reported failure (negative return), with HDF5's
// own reason in parentheses.
template <class R>
R check(R r, std::string_view what)
{
    if (r < 0) {
        const std::string detail = error_detail();
        throw Error("HDF5: " + std::string(what) + " failed" + (detail.empty() ? "" : " (" + detail + ")"));
    }
    return r;
}

// One identifier and the function that releases it.
class Id {
public:
    static constexpr hid_t invalid = -1;  // H5I_INVALID_HID
    using Closer = herr_t (*)(hid_t);

    Id() = default;
    Id(hid_t id, Closer close, std::string_view what) : id_(check(id, what)), close_(close) {}
    Id(Id&& o) noexcept : id_(std::exchange(o.id_, invalid)), close_(o.close_) {}
    Id& operator=(Id&& o) noexcept
    {
        if (this != &o) {
            reset();
            id_ = std::exchange(o.id_, invalid);
            close_ = o.close_;
        }
        return *this;
    }
    Id(const Id&) = delete;
    Id& operator=(const Id&) = delete;
    ~Id() { reset(); }

    hid_t get() const { return id_; }
    operator hid_t() const { return id_; }  // NOLINT: passed straight to the C API
    bool valid() const { return id_ >= 0; }

    // Gives the identifier up without closing it (a parallel file must not be closed by
    // one rank alone when the others are not in step).
    hid_t release() { return std::exchange(id_, invalid); }

    // Closes now and reports failure (a destructor cannot).
    void close()
    {
        if (id_ >= 0) check(close_(std::exchange(id_, invalid)), "close");
    }

private:
    void reset()
    {
        if (id_ >= 0) close_(std::exchange(id_, invalid));
    }

    hid_t id_ = invalid;
    Closer close_ = nullptr;
};

}  // namespace superball::h5
