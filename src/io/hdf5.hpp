// RAII ownership of HDF5 identifiers, and each HDF5 call the result files need wrapped
// once, with typed errors: Error when a call fails.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "hdf5_id.hpp"

static_assert(std::is_same_v<hid_t, std::int64_t> && std::is_same_v<herr_t, int>,
              "hdf5_id.hpp declares hid_t and herr_t as this HDF5 does");

namespace superball::h5 {

inline Id file_id(hid_t id, std::string_view what) { return {id, H5Fclose, what}; }
inline Id group_id(hid_t id, std::string_view what) { return {id, H5Gclose, what}; }
inline Id dataset_id(hid_t id, std::string_view what) { return {id, H5Dclose, what}; }
inline Id space_id(hid_t id, std::string_view what) { return {id, H5Sclose, what}; }
inline Id plist_id(hid_t id, std::string_view what) { return {id, H5Pclose, what}; }
inline Id type_id(hid_t id, std::string_view what) { return {id, H5Tclose, what}; }
inline Id attribute_id(hid_t id, std::string_view what) { return {id, H5Aclose, what}; }
inline Id object_id(hid_t id, std::string_view what) { return {id, H5Oclose, what}; }

// A box's origin or extent (job/tiles.hpp's Extent, an entry per range axis) as HDF5's dimensions.
inline std::vector<hsize_t> to_hsize(std::span<const std::uint64_t> e) { return {e.begin(), e.end()}; }

// HDF5 prints its own error stack by default; the messages here say what failed.
void silence_errors();

// ------------------------------------------------------------------------------- files

// True if `path` begins with HDF5's signature (it may still be damaged further in).
bool is_hdf5(const std::filesystem::path& path);
Id create_file(const std::filesystem::path& path, hid_t fapl);
Id open_file(const std::filesystem::path& path, bool writable, hid_t fapl = H5P_DEFAULT);
// A file access list for the HDF5 1.10 format (chunk indexes whose memory and file cost
// do not grow with the number of chunks; read by h5py, netCDF-4, ParaView) that aligns
// every object of at least `alignment` bytes on a multiple of it (0: no alignment).
Id file_access(std::uint64_t alignment);

// ------------------------------------------------------------------------------ objects

enum class ObjectType { missing, group, dataset, other };
// What `path` names in `loc` (following links; a dangling link is missing).
ObjectType object_type(hid_t loc, const std::string& path);
Id open_dataset(hid_t loc, const std::string& path);
Id create_group(hid_t loc, const std::string& path);
// A soft link `path` -> `target`.
void create_soft_link(hid_t loc, const std::string& target, const std::string& path);

// The element type and extent of a dataset or attribute, for validation.
enum class TypeClass { integer, floating, string, other };
struct Shape {
    TypeClass type = TypeClass::other;
    std::size_t bytes = 0;     // of one element
    bool is_signed = false;    // integers
    bool little_endian = true; // integers and floating-point numbers
    bool variable_length = false;  // strings: variable length (`bytes` is then a pointer's)
    bool scalar = false;       // a scalar dataspace
    std::vector<hsize_t> dims; // empty for a scalar
    std::uint64_t elements() const;
};
Shape dataset_shape_of(hid_t dataset);
// Dimensions of a dataset.
std::vector<hsize_t> dataset_shape(hid_t dataset);
// How a dataset is stored: its chunk dimensions (empty unless chunked), how many filters
// its chunks pass through, and whether all of its data has storage (every chunk of a
// chunked dataset allocated, the whole extent of a contiguous one): a dataset without is
// missing data, which HDF5 would silently read as fill values.
struct Storage {
    std::vector<hsize_t> chunk;
    int filters = 0;
    int deflate_level = -1;  // the deflate filter's level; -1 without one
    bool shuffle = false;    // the shuffle filter is in the pipeline
    bool allocated = false;
};
Storage dataset_storage(hid_t dataset);
// Address of an object's header in its file: what an HDF5 1.10 object reference holds.
haddr_t object_address(hid_t object);
// Byte offset of a contiguous dataset's data in the file.
std::uint64_t contiguous_offset(hid_t dataset);
// Byte offset of the chunk whose first element is at `coords`.
std::uint64_t chunk_offset(hid_t dataset, const std::vector<hsize_t>& coords);

// ------------------------------------------------------------------------------- datasets

// How a new dataset is stored (its creation properties).
struct Creation {
    std::vector<hsize_t> chunk;  // empty: contiguous
    int deflate = 0;             // above 0: shuffle, then deflate at this level
    H5D_alloc_time_t alloc = H5D_ALLOC_TIME_EARLY;
    std::optional<H5D_fill_time_t> fill;  // HDF5's default unless set
};
// Dataset `path` in `loc` of file type `type` and dimensions `dims` (empty: a scalar).
Id create_dataset(hid_t loc, const std::string& path, hid_t type, const std::vector<hsize_t>& dims, const Creation& how);
// Bytes of one element of a datatype.
std::size_t type_size(hid_t type);
// A contiguous dataset's data in its file: [offset, offset + bytes), nullopt if unallocated.
std::optional<std::pair<std::uint64_t, std::uint64_t>> contiguous_range(hid_t dataset);
// Chunks a chunked dataset has allocated.
std::uint64_t allocated_chunks(hid_t dataset);
// The chunk whose first element is at `origin` as stored (through no filter), if it is
// stored in exactly `bytes` bytes and can be read; nullopt otherwise.
std::optional<std::vector<std::byte>> read_raw_chunk(hid_t dataset, const std::vector<hsize_t>& origin, std::uint64_t bytes);
void flush(hid_t file);
void delete_attribute(hid_t obj, const std::string& name);
// Removes the link `path` of `loc` (the object goes with its last link).
void unlink(hid_t loc, const std::string& path);

// Typed reads and writes (HighFive's shape): T's native memory type, converted from and to
// the file's by HDF5; `what` names the data in errors.
template <class T>
hid_t native_type()
{
    if constexpr (std::is_same_v<T, std::uint8_t>) return H5T_NATIVE_UINT8;
    else if constexpr (std::is_same_v<T, std::uint32_t>) return H5T_NATIVE_UINT32;
    else if constexpr (std::is_same_v<T, std::uint64_t>) return H5T_NATIVE_UINT64;
    else if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
    else static_assert(sizeof(T) == 0, "no native HDF5 type for this element type");
}
// The whole dataset into `out` (its elements in row-major order; out.size() of them).
template <class T>
void read(hid_t dataset, std::span<T> out, const std::string& what)
{
    check(H5Dread(dataset, native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), "read " + what);
}
// `in` as the whole dataset.
template <class T>
void write(hid_t dataset, std::span<const T> in, const std::string& what)
{
    check(H5Dwrite(dataset, native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, in.data()), "write " + what);
}
// The box [start, start + count) of a dataset into `out` (row-major over the box).
template <class T>
void read_box(hid_t dataset, const std::vector<hsize_t>& start, const std::vector<hsize_t>& count, std::span<T> out,
              const std::string& what);

// --------------------------------------------------------------------------- attributes

// Scalar and 1-D attributes on an object; an existing attribute of the name is replaced.
void write_attribute(hid_t obj, const std::string& name, double value);
void write_attribute(hid_t obj, const std::string& name, std::int64_t value);
void write_attribute(hid_t obj, const std::string& name, const std::string& value);
void write_attribute(hid_t obj, const std::string& name, const char* value);
void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values);
void write_attribute(hid_t obj, const std::string& name, const std::vector<std::uint64_t>& values);
// Text as a fixed-length ASCII string: netCDF reads it as a text (NC_CHAR) attribute,
// which every netCDF tool handles (NCO drops NC_STRING `coordinates`); for CF's
// descriptive attributes. `value` must be ASCII.
void write_text_attribute(hid_t obj, const std::string& name, const std::string& value);
// An array of unsigned bytes (netCDF's flag_values must have the variable's own type).
void write_attribute(hid_t obj, const std::string& name, std::span<const std::uint8_t> values);

bool has_attribute(hid_t obj, const std::string& name);
// nullopt when the object has no attribute of that name.
std::optional<Shape> attribute_shape(hid_t obj, const std::string& name);
double read_double_attribute(hid_t obj, const std::string& name);
std::int64_t read_int_attribute(hid_t obj, const std::string& name);
std::string read_string_attribute(hid_t obj, const std::string& name);
std::vector<std::uint64_t> read_u64_vector_attribute(hid_t obj, const std::string& name);
std::vector<std::string> read_string_vector_attribute(hid_t obj, const std::string& name);

// ---------------------------------------------------------------------- dimension scales

// Makes `dataset` a dimension scale named `name` (netCDF-4 and xarray read it as a
// coordinate variable), and attaches it to dimension `dim` of `data`.
void make_dimension_scale(hid_t dataset, const std::string& name);
void attach_dimension_scale(hid_t data, hid_t scale, unsigned dim);
// The scales attached to each dimension of `data`, as object addresses, read from its
// DIMENSION_LIST attribute; empty if it has none. Checks the attribute's type and shape
// before reading it (HDF5's own H5DS functions trust them) and throws Error when they are
// not those of the dimension-scale API.
std::vector<std::vector<haddr_t>> attached_scales(hid_t data);

// ------------------------------------------------------------------------- global heap

// HDF5 1.10 keeps variable-length data (text attributes, DIMENSION_LIST) in global heap
// collections, which have no checksum, and trusts the sizes of their objects: a damaged
// size makes it copy past its buffers when the data are read (a crash, or a hang, not an
// error). Walks every collection found in the file's bytes outside the ranges `skip` (raw
// data, [offset, offset + size)) as HDF5 will, and returns the offset of the first whose
// objects do not fit it exactly, or nullopt. To be called before any variable-length
// value of the file is read.
std::optional<std::uint64_t> damaged_global_heap(const std::filesystem::path& path,
                                                 const std::vector<std::pair<std::uint64_t, std::uint64_t>>& skip);

// --------------------------------------------------------------------------- selections

// Selects the box [start, start + count) of `space` (op: H5S_SELECT_SET or _OR).
void select_box(hid_t space, const std::vector<hsize_t>& start, const std::vector<hsize_t>& count,
                H5S_seloper_t op = H5S_SELECT_SET);
// A simple dataspace of the given dimensions.
Id simple_space(const std::vector<hsize_t>& dims);
// Rows [first, first + rows) of a dataset of one or two dimensions, every column, as
// unsigned 64-bit integers, into `out` (rows x columns values); `what` names it in errors.
void read_rows(hid_t dataset, hsize_t first, hsize_t rows, std::span<std::uint64_t> out, const std::string& what);

template <class T>
void read_box(hid_t dataset, const std::vector<hsize_t>& start, const std::vector<hsize_t>& count, std::span<T> out,
              const std::string& what)
{
    const Id space = space_id(H5Dget_space(dataset), "H5Dget_space " + what);
    select_box(space, start, count);
    const Id memory = simple_space(count);
    check(H5Dread(dataset, native_type<T>(), memory, space, H5P_DEFAULT, out.data()), "read " + what);
}

}  // namespace superball::h5
