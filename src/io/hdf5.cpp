#include "hdf5.hpp"

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
    return innermost;
}

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

}  // namespace

void write_attribute(hid_t obj, const std::string& name, double value)
{
    write_scalar(obj, name, H5T_NATIVE_DOUBLE, value);
}

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

void write_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values)
{
    const Id type = variable_string_type();
    std::vector<const char*> p;
    for (const auto& v : values) p.push_back(v.c_str());
    const hsize_t n = p.size();
    const Id space = space_id(H5Screate_simple(1, &n, nullptr), "H5Screate_simple");
    const Id attr = create_attribute(obj, name, type, space);
    check(H5Awrite(attr, type, p.data()), "H5Awrite " + name);
}

void write_attribute(hid_t obj, const std::string& name, const std::vector<std::uint64_t>& values)
{
    const hsize_t n = values.size();
    const Id space = space_id(H5Screate_simple(1, &n, nullptr), "H5Screate_simple");
    const Id attr = create_attribute(obj, name, H5T_NATIVE_UINT64, space);
    check(H5Awrite(attr, H5T_NATIVE_UINT64, values.data()), "H5Awrite " + name);
}

bool has_attribute(hid_t obj, const std::string& name) { return check(H5Aexists(obj, name.c_str()), "H5Aexists") > 0; }

double read_double_attribute(hid_t obj, const std::string& name)
{
    double v = 0;
    check(H5Aread(open_attribute(obj, name), H5T_NATIVE_DOUBLE, &v), "H5Aread " + name);
    return v;
}

std::int64_t read_int_attribute(hid_t obj, const std::string& name)
{
    std::int64_t v = 0;
    check(H5Aread(open_attribute(obj, name), H5T_NATIVE_INT64, &v), "H5Aread " + name);
    return v;
}

std::string read_string_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_attribute(obj, name);
    const Id file_type = type_id(H5Aget_type(attr), "H5Aget_type");
    if (H5Tget_class(file_type) != H5T_STRING) throw Error("HDF5: attribute " + name + " is not a string");
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
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    const hssize_t n = check(H5Sget_simple_extent_npoints(space), "H5Sget_simple_extent_npoints");
    std::vector<std::uint64_t> v(static_cast<std::size_t>(n));
    check(H5Aread(attr, H5T_NATIVE_UINT64, v.data()), "H5Aread " + name);
    return v;
}

std::vector<std::string> read_string_vector_attribute(hid_t obj, const std::string& name)
{
    const Id attr = open_attribute(obj, name);
    const Id space = space_id(H5Aget_space(attr), "H5Aget_space");
    const auto n = static_cast<std::size_t>(check(H5Sget_simple_extent_npoints(space), "H5Sget_simple_extent_npoints"));
    const Id type = variable_string_type();
    std::vector<char*> p(n, nullptr);
    check(H5Aread(attr, type, p.data()), "H5Aread " + name);
    std::vector<std::string> out;
    for (char* s : p) {
        out.emplace_back(s ? s : "");
        H5free_memory(s);
    }
    return out;
}

std::vector<hsize_t> dataset_shape(hid_t dataset)
{
    const Id space = space_id(H5Dget_space(dataset), "H5Dget_space");
    const int rank = check(H5Sget_simple_extent_ndims(space), "H5Sget_simple_extent_ndims");
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    check(H5Sget_simple_extent_dims(space, dims.data(), nullptr), "H5Sget_simple_extent_dims");
    return dims;
}

}  // namespace superball::h5
