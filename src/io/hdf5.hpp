// RAII ownership of HDF5 identifiers and the few typed helpers the result file needs.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace superball::h5 {

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
    using Closer = herr_t (*)(hid_t);

    Id() = default;
    Id(hid_t id, Closer close, std::string_view what) : id_(check(id, what)), close_(close) {}
    Id(Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
    Id& operator=(Id&& o) noexcept
    {
        if (this != &o) {
            reset();
            id_ = std::exchange(o.id_, H5I_INVALID_HID);
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

    // Gives the identifier up without closing it (ResultFile: a parallel file must not be
    // closed by one rank alone).
    hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }

    // Closes now and reports failure (a destructor cannot).
    void close()
    {
        if (id_ >= 0) check(close_(std::exchange(id_, H5I_INVALID_HID)), "close");
    }

private:
    void reset()
    {
        if (id_ >= 0) close_(std::exchange(id_, H5I_INVALID_HID));
    }

    hid_t id_ = H5I_INVALID_HID;
    Closer close_ = nullptr;
};

inline Id file_id(hid_t id, std::string_view what) { return {id, H5Fclose, what}; }
inline Id group_id(hid_t id, std::string_view what) { return {id, H5Gclose, what}; }
inline Id dataset_id(hid_t id, std::string_view what) { return {id, H5Dclose, what}; }
inline Id space_id(hid_t id, std::string_view what) { return {id, H5Sclose, what}; }
inline Id plist_id(hid_t id, std::string_view what) { return {id, H5Pclose, what}; }
inline Id type_id(hid_t id, std::string_view what) { return {id, H5Tclose, what}; }
inline Id attribute_id(hid_t id, std::string_view what) { return {id, H5Aclose, what}; }

// HDF5 prints its own error stack by default; the messages here say what failed.
void silence_errors();

// Scalar and 1-D attributes on an object.
void write_attribute(hid_t obj, const std::string& name, double value);
void write_attribute(hid_t obj, const std::string& name, std::int64_t value);
void write_attribute(hid_t obj, const std::string& name, const std::string& value);
void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values);
void write_attribute(hid_t obj, const std::string& name, const std::vector<std::uint64_t>& values);

bool has_attribute(hid_t obj, const std::string& name);
double read_double_attribute(hid_t obj, const std::string& name);
std::int64_t read_int_attribute(hid_t obj, const std::string& name);
std::string read_string_attribute(hid_t obj, const std::string& name);
std::vector<std::uint64_t> read_u64_vector_attribute(hid_t obj, const std::string& name);
std::vector<std::string> read_string_vector_attribute(hid_t obj, const std::string& name);

// Dimensions of a dataset.
std::vector<hsize_t> dataset_shape(hid_t dataset);

}  // namespace superball::h5
