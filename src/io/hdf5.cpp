#include "hdf5.hpp"

#include <H5DSpublic.h>

#include <algorithm>
#include <utility>
#include <fstream>
#include <initializer_list>

namespace superball::h5 {

void silence_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

std::string error_detail()
{
    std::string innermost;
    // Walking upward, entry 0 is the most specific one.
    const auto first = [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
        if (n == 0 && e->desc != nullptr) *static_cast<std::string*>(out) = e->desc;
        return 0;
    };
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, first, &innermost);
    // The file drivers' reports run to several lines ("file write failed: time = ...,
    // filename = ..., errno = 28, error message = 'No space left on device', ..."): keep
    // what they failed at and the system's reason.
    const std::string key = "error message = '";
    if (const auto at = innermost.find(key); at != std::string::npos) {
        const auto end = innermost.find('\'', at + key.size());
        const auto colon = innermost.find(':');
        return innermost.substr(0, colon) + ": " + innermost.substr(at + key.size(), end - at - key.size());
    }
    return innermost;
}

// ------------------------------------------------------------------------------- files

bool is_hdf5(const std::filesystem::path& path)
{
    // HDF5 looks for its signature at 0, 512, 1024, ... (a user block may come first);
    // read it ourselves: H5Fis_hdf5 reports failure and "not HDF5" alike.
    static constexpr char signature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
    std::ifstream in(path, std::ios::binary);
    char buf[8];
    for (std::streamoff at = 0; in; at = at == 0 ? 512 : at * 2) {
        in.seekg(at);
        if (!in.read(buf, sizeof buf)) return false;
        if (std::equal(buf, buf + 8, signature)) return true;
        if (at >= (std::streamoff{1} << 30)) return false;
    }
    return false;
}

// Every file opened or created through here: HDF5's own printing of its error stack is off
// (the errors thrown say what failed), whoever the caller.
Id create_file(const std::filesystem::path& path, hid_t fapl)
{
    silence_errors();
    return file_id(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), "create " + path.string());
}

Id open_file(const std::filesystem::path& path, bool writable, hid_t fapl)
{
    silence_errors();
    return file_id(H5Fopen(path.c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl), "open " + path.string());
}

Id file_access(std::uint64_t alignment)
{
    Id fapl = plist_id(H5Pcreate(H5P_FILE_ACCESS), "H5Pcreate");
    check(H5Pset_libver_bounds(fapl, H5F_LIBVER_V110, H5F_LIBVER_LATEST), "H5Pset_libver_bounds");
    if (alignment > 1) check(H5Pset_alignment(fapl, alignment, alignment), "H5Pset_alignment");
    return fapl;
}

// ------------------------------------------------------------------------------ objects

ObjectType object_type(hid_t loc, const std::string& path)
{
    // Every component must exist before H5Oget_info_by_name may be asked about the last.
    std::size_t at = path.front() == '/' ? 1 : 0;
    for (;;) {
        const std::size_t slash = path.find('/', at);
        const std::string prefix = path.substr(0, slash);
        if (check(H5Lexists(loc, prefix.c_str(), H5P_DEFAULT), "H5Lexists " + prefix) <= 0) return ObjectType::missing;
        if (check(H5Oexists_by_name(loc, prefix.c_str(), H5P_DEFAULT), "H5Oexists " + prefix) <= 0) {
            return ObjectType::missing;  // a dangling soft link
        }
        if (slash == std::string::npos) break;
        at = slash + 1;
    }
    H5O_info_t info{};
    check(H5Oget_info_by_name2(loc, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT), "H5Oget_info " + path);
    switch (info.type) {
        case H5O_TYPE_GROUP: return ObjectType::group;
        case H5O_TYPE_DATASET: return ObjectType::dataset;
        default: return ObjectType::other;
    }
}

Id open_dataset(hid_t loc, const std::string& path)
{
    return dataset_id(H5Dopen2(loc, path.c_str(), H5P_DEFAULT), "open " + path);
}

Id create_group(hid_t loc, const std::string& path)
{
    return group_id(H5Gcreate2(loc, path.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "create " + path);
}

void create_soft_link(hid_t loc, const std::string& target, const std::string& path)
{
    check(H5Lcreate_soft(target.c_str(), loc, path.c_str(), H5P_DEFAULT, H5P_DEFAULT), "link " + path);
}

std::uint64_t Shape::elements() const
{
    std::uint64_t n = 1;
    for (const hsize_t d : dims) n *= d;
    return n;
}

namespace {

Shape shape_of(hid_t type, hid_t space)
{
    Shape s;
    switch (H5Tget_class(type)) {
        case H5T_INTEGER:
            s.type = TypeClass::integer;
            s.is_signed = H5Tget_sign(type) == H5T_SGN_2;
            s.little_endian = H5Tget_order(type) == H5T_ORDER_LE;
            break;
        case H5T_FLOAT:
            s.type = TypeClass::floating;
            s.little_endian = H5Tget_order(type) == H5T_ORDER_LE;
            break;
        case H5T_STRING:
            s.type = TypeClass::string;
            s.variable_length = H5Tis_variable_str(type) > 0;
            break;
        default: s.type = TypeClass::other; break;
    }
    s.bytes = H5Tget_size(type);
    const H5S_class_t cls = H5Sget_simple_extent_type(space);
    s.scalar = cls == H5S_SCALAR;
    if (cls == H5S_SIMPLE) {
        const int rank = check(H5Sget_simple_extent_ndims(space), "H5Sget_simple_extent_ndims");
        s.dims.resize(static_cast<std::size_t>(rank));
        check(H5Sget_simple_extent_dims(space, s.dims.data(), nullptr), "H5Sget_simple_extent_dims");
    } else if (cls == H5S_NULL) {
        s.dims = {0};
    }
    return s;
}

}  // namespace

Shape dataset_shape_of(hid_t dataset)
{
    const Id type = type_id(H5Dget_type(dataset), "H5Dget_type");
    const Id space = space_id(H5Dget_space(dataset), "H5Dget_space");
    return shape_of(type, space);
}

std::vector<hsize_t> dataset_shape(hid_t dataset)
{
    const Id space = space_id(H5Dget_space(dataset), "H5Dget_space");
    const int rank = check(H5Sget_simple_extent_ndims(space), "H5Sget_simple_extent_ndims");
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    check(H5Sget_simple_extent_dims(space, dims.data(), nullptr), "H5Sget_simple_extent_dims");
    return dims;
}

Storage dataset_storage(hid_t dataset)
{
    Storage st;
    const Id dcpl = plist_id(H5Dget_create_plist(dataset), "H5Dget_create_plist");
    const Shape s = dataset_shape_of(dataset);
    const H5D_layout_t layout = H5Pget_layout(dcpl);
    if (layout == H5D_CHUNKED) {
        st.chunk.resize(s.dims.size());
        const int rank = check(H5Pget_chunk(dcpl, static_cast<int>(st.chunk.size()), st.chunk.data()), "H5Pget_chunk");
        if (static_cast<std::size_t>(rank) != s.dims.size()) throw Error("HDF5: the chunks' rank differs from the dataset's");
        st.filters = check(H5Pget_nfilters(dcpl), "H5Pget_nfilters");
        for (int i = 0; i < st.filters; ++i) {
            unsigned flags = 0, values[4] = {};
            std::size_t n = 4;
            const H5Z_filter_t f = H5Pget_filter2(dcpl, static_cast<unsigned>(i), &flags, &n, values, 0, nullptr, nullptr);
            if (f == H5Z_FILTER_SHUFFLE) st.shuffle = true;
            if (f == H5Z_FILTER_DEFLATE) st.deflate_level = n > 0 ? static_cast<int>(values[0]) : 0;
        }
        // Chunks expected: the grid of chunks over the extent.
        hsize_t expected = 1;
        for (std::size_t k = 0; k < s.dims.size(); ++k) {
            if (st.chunk[k] == 0) throw Error("HDF5: a chunk dimension is 0");
            expected *= (s.dims[k] + st.chunk[k] - 1) / st.chunk[k];
        }
        const Id space = space_id(H5Dget_space(dataset), "H5Dget_space");
        hsize_t chunks = 0;
        check(H5Dget_num_chunks(dataset, space, &chunks), "H5Dget_num_chunks");
        st.allocated = chunks == expected;
    } else if (layout == H5D_CONTIGUOUS || layout == H5D_COMPACT) {
        st.allocated = H5Dget_storage_size(dataset) == s.elements() * s.bytes;
    }
    return st;
}

haddr_t object_address(hid_t object)
{
    H5O_info_t info{};
    check(H5Oget_info2(object, &info, H5O_INFO_BASIC), "H5Oget_info");
    return info.addr;
}

std::uint64_t contiguous_offset(hid_t dataset)
{
    const haddr_t a = H5Dget_offset(dataset);
    if (a == HADDR_UNDEF) throw Error("HDF5: H5Dget_offset failed (not a contiguous dataset with its space allocated)");
    return a;
}

std::uint64_t chunk_offset(hid_t dataset, const std::vector<hsize_t>& coords)
{
    unsigned filter_mask = 0;
    haddr_t addr = HADDR_UNDEF;
    hsize_t size = 0;
    check(H5Dget_chunk_info_by_coord(dataset, coords.data(), &filter_mask, &addr, &size), "H5Dget_chunk_info_by_coord");
    if (addr == HADDR_UNDEF) throw Error("HDF5: chunk not allocated");
    return addr;
}

// --------------------------------------------------------------------------- attributes

namespace {

// Replaces an existing attribute: resume rewrites `complete` and `wall_seconds`.
Id create_attribute(hid_t obj, const std::string& name, hid_t type, hid_t space)
{
    if (check(H5Aexists(obj, name.c_str()), "H5Aexists " + name) > 0) check(H5Adelete(obj, name.c_str()), "H5Adelete " + name);
    return attribute_id(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "H5Acreate " + name);
}

template <class T>
void write_scalar(hid_t obj, const std::string& name, hid_t type, const T& value)
{
    const Id space = space_id(H5Screate(H5S_SCALAR), "H5Screate");
    const Id attr = create_attribute(obj, name, type, space);
    check(H5Awrite(attr, type, &value), "H5Awrite " + name);
}

Id variable_string_type()
{
    Id t = type_id(H5Tcopy(H5T_C_S1), "H5Tcopy");
    check(H5Tset_size(t, H5T_VARIABLE), "H5Tset_size");
    check(H5Tset_cset(t, H5T_CSET_UTF8), "H5Tset_cset");
    return t;
}

Id open_attribute(hid_t obj, const std::string& name)
{
    return attribute_id(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "H5Aopen " + name);
}

// The attribute, checked to hold exactly one value of the given class.
Id open_scalar(hid_t obj, const std::string& name, std::initializer_list<TypeClass> accepted, const char* expected)
{
    Id attr = open_attribute(obj, name);
    const Id type = type_id(H5Aget_type(attr), "H5Aget_type");
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    const Shape s = shape_of(type, space);
    if (std::find(accepted.begin(), accepted.end(), s.type) == accepted.end() || s.elements() != 1) {
        throw Error("attribute " + name + " is not " + expected);
    }
    return attr;
}

}  // namespace

void write_attribute(hid_t obj, const std::string& name, double value) { write_scalar(obj, name, H5T_NATIVE_DOUBLE, value); }

void write_attribute(hid_t obj, const std::string& name, std::int64_t value)
{
    write_scalar(obj, name, H5T_NATIVE_INT64, value);
}

void write_attribute(hid_t obj, const std::string& name, const std::string& value)
{
    const Id type = variable_string_type();
    const char* p = value.c_str();
    write_scalar(obj, name, type, p);
}

void write_attribute(hid_t obj, const std::string& name, const char* value) { write_attribute(obj, name, std::string(value)); }

void write_text_attribute(hid_t obj, const std::string& name, const std::string& value)
{
    // As netCDF-4 itself writes text: the characters, null-terminated if there is room.
    const Id type = type_id(H5Tcopy(H5T_C_S1), "H5Tcopy");
    check(H5Tset_size(type, std::max<std::size_t>(value.size(), 1)), "H5Tset_size");
    check(H5Tset_strpad(type, H5T_STR_NULLTERM), "H5Tset_strpad");
    check(H5Tset_cset(type, H5T_CSET_ASCII), "H5Tset_cset");
    const Id space = space_id(H5Screate(H5S_SCALAR), "H5Screate");
    const Id attr = create_attribute(obj, name, type, space);
    std::string buf = value;
    buf.resize(std::max<std::size_t>(value.size(), 1), '\0');
    check(H5Awrite(attr, type, buf.data()), "H5Awrite " + name);
}

void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values)
{
    const Id type = variable_string_type();
    std::vector<const char*> p;
    for (const auto& v : values) p.push_back(v.c_str());
    const Id space = simple_space({p.size()});
    const Id attr = create_attribute(obj, name, type, space);
    check(H5Awrite(attr, type, p.data()), "H5Awrite " + name);
}

void write_attribute(hid_t obj, const std::string& name, const std::vector<std::uint64_t>& values)
{
    const Id space = simple_space({values.size()});
    const Id attr = create_attribute(obj, name, H5T_STD_U64LE, space);
    check(H5Awrite(attr, H5T_NATIVE_UINT64, values.data()), "H5Awrite " + name);
}

void write_attribute(hid_t obj, const std::string& name, std::span<const std::uint8_t> values)
{
    const Id space = simple_space({values.size()});
    const Id attr = create_attribute(obj, name, H5T_STD_U8LE, space);
    check(H5Awrite(attr, H5T_NATIVE_UINT8, values.data()), "H5Awrite " + name);
}

bool has_attribute(hid_t obj, const std::string& name) { return check(H5Aexists(obj, name.c_str()), "H5Aexists") > 0; }

std::optional<Shape> attribute_shape(hid_t obj, const std::string& name)
{
    if (!has_attribute(obj, name)) return std::nullopt;
    const Id attr = open_attribute(obj, name);
    const Id type = type_id(H5Aget_type(attr), "H5Aget_type");
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    return shape_of(type, space);
}

double read_double_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_scalar(obj, name, {TypeClass::floating, TypeClass::integer}, "a number");
    double v = 0;
    check(H5Aread(attr, H5T_NATIVE_DOUBLE, &v), "H5Aread " + name);
    return v;
}

std::int64_t read_int_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_scalar(obj, name, {TypeClass::integer}, "an integer");
    std::int64_t v = 0;
    check(H5Aread(attr, H5T_NATIVE_INT64, &v), "H5Aread " + name);
    return v;
}

std::string read_string_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_scalar(obj, name, {TypeClass::string}, "a text");
    const Id file_type = type_id(H5Aget_type(attr), "H5Aget_type");
    if (H5Tis_variable_str(file_type) > 0) {
        const Id type = variable_string_type();
        char* p = nullptr;
        check(H5Aread(attr, type, &p), "H5Aread " + name);
        std::string s = p ? p : "";
        H5free_memory(p);
        return s;
    }
    const std::size_t n = H5Tget_size(file_type);
    std::string s(n, '\0');
    check(H5Aread(attr, file_type, s.data()), "H5Aread " + name);
    return s.substr(0, s.find('\0'));
}

std::vector<std::uint64_t> read_u64_vector_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_attribute(obj, name);
    const Id type = type_id(H5Aget_type(attr), "H5Aget_type");
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    const Shape s = shape_of(type, space);
    if (s.type != TypeClass::integer) throw Error("attribute " + name + " is not a list of integers");
    std::vector<std::uint64_t> v(s.elements());
    check(H5Aread(attr, H5T_NATIVE_UINT64, v.data()), "H5Aread " + name);
    return v;
}

std::vector<std::string> read_string_vector_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_attribute(obj, name);
    const Id file_type = type_id(H5Aget_type(attr), "H5Aget_type");
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    const Shape s = shape_of(file_type, space);
    if (s.type != TypeClass::string) throw Error("attribute " + name + " is not a list of texts");
    const auto n = static_cast<std::size_t>(s.elements());
    std::vector<std::string> out;
    if (H5Tis_variable_str(file_type) > 0) {
        const Id type = variable_string_type();
        std::vector<char*> p(n, nullptr);
        check(H5Aread(attr, type, p.data()), "H5Aread " + name);
        for (char* c : p) {
            out.emplace_back(c ? c : "");
            H5free_memory(c);
        }
        return out;
    }
    const std::size_t size = H5Tget_size(file_type);
    std::string buf(n * size, '\0');
    check(H5Aread(attr, file_type, buf.data()), "H5Aread " + name);
    for (std::size_t i = 0; i < n; ++i) {
        const std::string item = buf.substr(i * size, size);
        out.push_back(item.substr(0, item.find('\0')));
    }
    return out;
}

// ---------------------------------------------------------------------- dimension scales

void make_dimension_scale(hid_t dataset, const std::string& name)
{
    check(H5DSset_scale(dataset, name.c_str()), "H5DSset_scale " + name);
}

void attach_dimension_scale(hid_t data, hid_t scale, unsigned dim)
{
    check(H5DSattach_scale(data, scale, dim), "H5DSattach_scale");
}

std::vector<std::vector<haddr_t>> attached_scales(hid_t data)
{
    static constexpr const char* name = "DIMENSION_LIST";
    if (!has_attribute(data, name)) return {};
    const Id attr = open_attribute(data, name);
    const Id type = type_id(H5Aget_type(attr), "H5Aget_type");
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    const int rank = check(H5Sget_simple_extent_ndims(space), "H5Sget_simple_extent_ndims");
    const Id base = H5Tget_class(type) == H5T_VLEN ? type_id(H5Tget_super(type), "H5Tget_super") : Id{};
    if (H5Sget_simple_extent_type(space) != H5S_SIMPLE || rank != 1 || !base.valid() ||
        H5Tequal(base, H5T_STD_REF_OBJ) <= 0) {
        throw Error("attribute DIMENSION_LIST is not a list of object references per dimension");
    }
    hsize_t n = 0;
    check(H5Sget_simple_extent_dims(space, &n, nullptr), "H5Sget_simple_extent_dims");
    if (n > 32) throw Error("attribute DIMENSION_LIST lists more than 32 dimensions");
    const Id memory = type_id(H5Tvlen_create(H5T_STD_REF_OBJ), "H5Tvlen_create");
    std::vector<hvl_t> lists(n, hvl_t{0, nullptr});
    check(H5Aread(attr, memory, lists.data()), "H5Aread DIMENSION_LIST");
    std::vector<std::vector<haddr_t>> out(n);
    for (hsize_t k = 0; k < n; ++k) {
        const auto* refs = static_cast<const hobj_ref_t*>(lists[k].p);
        if (refs != nullptr) out[k].assign(refs, refs + lists[k].len);
    }
    check(H5Dvlen_reclaim(memory, space, H5P_DEFAULT, lists.data()), "H5Dvlen_reclaim");
    return out;
}

// ------------------------------------------------------------------------- global heap

namespace {

std::uint64_t little_endian(const unsigned char* p, int bytes)
{
    std::uint64_t v = 0;
    for (int i = bytes; i-- > 0;) v = (v << 8) | p[i];
    return v;
}

// Whether the collection at `at` (its signature checked) is whole: objects as HDF5's
// H5HG__cache_heap_deserialize walks them (a 16-byte header: index, references, reserved,
// size; then the data, padded to 8 bytes; index 0 is the free space, its size counting its
// header), each inside the collection, the last ending exactly at its end.
bool collection_intact(std::ifstream& in, std::uint64_t at, std::uint64_t file_size)
{
    unsigned char header[16];
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(header), sizeof header)) return false;
    // Version 1, three reserved zero bytes; else HDF5 refuses it itself (an error, no crash).
    if (header[4] != 1 || header[5] != 0 || header[6] != 0 || header[7] != 0) return true;
    const std::uint64_t size = little_endian(header + 8, 8);
    if (size < 4096 || size > file_size - at || size > (std::uint64_t{1} << 30)) return false;
    std::vector<unsigned char> heap(size);
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(heap.data()), static_cast<std::streamsize>(size))) return false;
    std::vector<std::uint8_t> seen(65536, 0);
    std::uint64_t p = 16;
    while (p < size) {
        if (size - p < 16) break;  // too small for an object: free space, as HDF5 takes it
        const auto index = static_cast<std::size_t>(little_endian(&heap[p], 2));
        const std::uint64_t object = little_endian(&heap[p + 8], 8);
        if (object > size) return false;
        const std::uint64_t need = index > 0 ? 16 + ((object + 7) / 8) * 8 : object;
        if (need < 16 || need > size - p) return false;
        if (index > 0 && std::exchange(seen[index], std::uint8_t{1}) != 0) return false;
        p += need;
    }
    return true;
}

}  // namespace

std::optional<std::uint64_t> damaged_global_heap(const std::filesystem::path& path,
                                                 const std::vector<std::pair<std::uint64_t, std::uint64_t>>& skip)
{
    std::error_code ec;
    const std::uint64_t file_size = std::filesystem::file_size(path, ec);
    if (ec) return std::nullopt;
    std::ifstream in(path, std::ios::binary);
    static constexpr char signature[] = {'G', 'C', 'O', 'L', '\x01', '\0', '\0', '\0'};
    constexpr std::uint64_t block = std::uint64_t{16} << 20;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges(skip);
    std::sort(ranges.begin(), ranges.end());
    std::string buf;
    std::uint64_t from = 0;
    const auto scan = [&](std::uint64_t a, std::uint64_t b) -> std::optional<std::uint64_t> {
        // Blocks overlapping by a signature's length less one, so none is cut in two.
        for (std::uint64_t pos = a; pos < b; pos += block - (sizeof signature - 1)) {
            const std::uint64_t n = std::min(block, b - pos);
            buf.resize(n);
            in.clear();
            in.seekg(static_cast<std::streamoff>(pos));
            in.read(buf.data(), static_cast<std::streamsize>(n));
            buf.resize(static_cast<std::size_t>(std::max<std::streamsize>(0, in.gcount())));
            for (std::size_t i = buf.find(signature, 0, sizeof signature); i != std::string::npos;
                 i = buf.find(signature, i + 1, sizeof signature)) {
                if (!collection_intact(in, pos + i, file_size)) return pos + i;
            }
            if (n < block) break;
        }
        return std::nullopt;
    };
    for (const auto& [offset, size] : ranges) {
        if (offset > from) {
            if (const auto bad = scan(from, std::min(offset, file_size))) return bad;
        }
        from = std::max(from, offset + size);
    }
    if (from < file_size) return scan(from, file_size);
    return std::nullopt;
}

// --------------------------------------------------------------------------- selections

void select_box(hid_t space, const std::vector<hsize_t>& start, const std::vector<hsize_t>& count, H5S_seloper_t op)
{
    check(H5Sselect_hyperslab(space, op, start.data(), nullptr, count.data(), nullptr), "H5Sselect_hyperslab");
}

Id simple_space(const std::vector<hsize_t>& dims)
{
    return space_id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), "H5Screate_simple");
}

void read_rows(hid_t dataset, hsize_t first, hsize_t rows, std::span<std::uint64_t> out, const std::string& what)
{
    const std::vector<hsize_t> dims = dataset_shape(dataset);
    if (dims.empty() || dims.size() > 2) throw Error(what + ": a dataset of one or two dimensions expected");
    std::vector<hsize_t> start{first}, count{rows};
    if (dims.size() == 2) {
        start.push_back(0);
        count.push_back(dims[1]);
    }
    if (out.size() != rows * (dims.size() == 2 ? dims[1] : 1)) throw std::logic_error("read_rows " + what + ": wrong buffer size");
    read_box(dataset, start, count, out, what);
}

Id create_dataset(hid_t loc, const std::string& path, hid_t type, const std::vector<hsize_t>& dims, const Creation& how)
{
    const Id space = dims.empty() ? space_id(H5Screate(H5S_SCALAR), "H5Screate") : simple_space(dims);
    const Id dcpl = plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
    if (!how.chunk.empty()) check(H5Pset_chunk(dcpl, static_cast<int>(how.chunk.size()), how.chunk.data()), "H5Pset_chunk");
    if (how.deflate > 0) {
        check(H5Pset_shuffle(dcpl), "H5Pset_shuffle");
        check(H5Pset_deflate(dcpl, static_cast<unsigned>(how.deflate)), "H5Pset_deflate");
    }
    check(H5Pset_alloc_time(dcpl, how.alloc), "H5Pset_alloc_time");
    if (how.fill) check(H5Pset_fill_time(dcpl, *how.fill), "H5Pset_fill_time");
    return dataset_id(H5Dcreate2(loc, path.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), "create " + path);
}

std::size_t type_size(hid_t type)
{
    const std::size_t n = H5Tget_size(type);
    if (n == 0) throw Error("H5Tget_size failed");
    return n;
}

std::optional<std::pair<std::uint64_t, std::uint64_t>> contiguous_range(hid_t dataset)
{
    const haddr_t at = H5Dget_offset(dataset);
    if (at == HADDR_UNDEF) return std::nullopt;
    return std::pair<std::uint64_t, std::uint64_t>{at, H5Dget_storage_size(dataset)};
}

std::uint64_t allocated_chunks(hid_t dataset)
{
    hsize_t chunks = 0;
    const Id space = space_id(H5Dget_space(dataset), "H5Dget_space");
    check(H5Dget_num_chunks(dataset, space, &chunks), "H5Dget_num_chunks");
    return chunks;
}

std::optional<std::vector<std::byte>> read_raw_chunk(hid_t dataset, const std::vector<hsize_t>& origin, std::uint64_t bytes)
{
    hsize_t stored = 0;
    if (H5Dget_chunk_storage_size(dataset, origin.data(), &stored) < 0 || stored != bytes) return std::nullopt;
    std::vector<std::byte> chunk(stored);
    std::uint32_t filters = 0;
    if (H5Dread_chunk(dataset, H5P_DEFAULT, origin.data(), &filters, chunk.data()) < 0) return std::nullopt;
    return chunk;
}

void flush(hid_t file) { check(H5Fflush(file, H5F_SCOPE_GLOBAL), "H5Fflush"); }

void delete_attribute(hid_t obj, const std::string& name) { check(H5Adelete(obj, name.c_str()), "H5Adelete " + name); }

void unlink(hid_t loc, const std::string& path) { check(H5Ldelete(loc, path.c_str(), H5P_DEFAULT), "H5Ldelete " + path); }

}  // namespace superball::h5
