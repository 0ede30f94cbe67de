// libFuzzer target for the file validator, ResultReader (tests/fuzz/run.sh builds and runs
// it). Fuzzing HDF5's own parser would find libhdf5's bugs, not ours, so the input is not
// a file: it is a list of edits applied to a small valid file written with the HDF5 API
// (a result or a partial file, from a few templates made at start-up):
//
//   byte 0            the template
//   then operations   delete or set an attribute (a value of some type and shape), set
//                     one value of a dataset, replace a dataset by one of another type,
//                     shape and storage, delete or hard-link an object; then, after a
//                     "raw" operation, writes of given bytes at offsets into the raw data
//                     (the datasets' contiguous storage or chunks, never HDF5's metadata)
//
// Bytes past the end read as 0. The edited file is then read as `superball info` and
// `analyse` read it: open, every axis, a box, outcome_counts, damaged_tiles, and
// identify_file. It must be accepted, with the invariants validation promises, or refused
// with InputError (FormatError); anything else, a crash or a sanitizer report is a finding.
#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "io/chunk_codec.hpp"
#include "io/hdf5.hpp"
#include "io/layout.hpp"
#include "io/partial_file.hpp"
#include "io/placed_chunks.hpp"
#include "io/result_metadata.hpp"
#include "io/result_reader.hpp"
#include "job/grid.hpp"
#include "job/job.hpp"

namespace {

namespace fs = std::filesystem;
using namespace superball;

void require(bool ok, const char* what)
{
    if (!ok) {
        std::fprintf(stderr, "fuzz_result: accepted file breaks an invariant: %s\n", what);
        std::abort();
    }
}

// ----------------------------------------------------------------------------- templates

// Small jobs: a canonical 2-D slice, a 3-D grid with a swept coefficient, a physical line.
constexpr const char* job_2d = R"([model]
e = 0.9
alpha = 0.9
[grid]
xi = { min = 0.0, max = 1.0, n = 24 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 20 }
[run]
max_bounces = 100
)";
constexpr const char* job_3d = R"([model]
e = { min = 0.5, max = 0.9, n = 3 }
alpha = 0.9
[grid]
xi = { min = 0.0, max = 1.0, n = 6 }
U = { min = -2.0, max = -0.5, n = 5 }
W = -1.0
[run]
max_bounces = 70000
)";
constexpr const char* job_1d = R"([model]
e = 0.8
alpha = 0.7
[grid]
coordinates = "physical"
x = { min = 0.0, max = 0.05, n = 50 }
u = -2.0
v = 2.0
omega = -100.0
[run]
max_bounces = 1000
)";

// Valid values for point i of a grid: every outcome, counts as it allows.
void valid_values(std::uint64_t i, std::int64_t max_bounces, std::uint32_t& count, std::uint8_t& outcome)
{
    outcome = static_cast<std::uint8_t>((i * 7 + i / 5) % 4);
    count = outcome == 0 ? 0 : outcome == 3 ? static_cast<std::uint32_t>(max_bounces) : static_cast<std::uint32_t>(i % 50);
}

std::vector<hsize_t> to_hsize(const Extent& e) { return {e.begin(), e.end()}; }

void write_box(hid_t d, hid_t memory_type, const Box& box, const void* values)
{
    const h5::Id space = h5::space_id(H5Dget_space(d), "H5Dget_space");
    h5::select_box(space, to_hsize(box.start), to_hsize(box.count));
    const h5::Id memory = h5::simple_space(to_hsize(box.count));
    h5::check(H5Dwrite(d, memory_type, memory, space, H5P_DEFAULT, values), "H5Dwrite");
}

// The run recorded in the templates' provenance attributes.
const Provenance template_run{"fuzz_result", "2026-01-01T00:00:00Z", 1, 1, 1, "scalar"};

// A complete result as io/final_result.cpp leaves it (written here through HDF5's filters):
// coordinate variables, attributes, the data in compressed chunks.
void write_result(const fs::path& path, const char* text)
{
    const Job job = parse_job(text, "template");
    const Grid grid(job);
    const Extent shape = grid.shape();
    const h5::Id file = h5::create_file(path, h5::file_access(0));
    const std::vector<h5::Id> axes = write_metadata(file, job, grid, layout::kind_result, {template_run, 0.25, true}, true);
    const Extent chunk = default_tile_shape(shape, 64);
    const auto create = [&](const char* name, hid_t type) {
        const h5::Id space = h5::simple_space(to_hsize(shape));
        const h5::Id dcpl = h5::plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
        const auto c = to_hsize(chunk);
        h5::check(H5Pset_chunk(dcpl, static_cast<int>(c.size()), c.data()), "H5Pset_chunk");
        h5::check(H5Pset_shuffle(dcpl), "H5Pset_shuffle");
        h5::check(H5Pset_deflate(dcpl, 4), "H5Pset_deflate");
        return h5::dataset_id(H5Dcreate2(file, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), name);
    };
    const h5::Id counts = create(layout::wall_bounces, count_type(job));
    const h5::Id outcomes = create(layout::outcome, H5T_STD_U8LE);
    describe_data(counts, outcomes, job, axes);
    const Box all{Extent(shape.size(), 0), shape};
    std::vector<std::uint32_t> c(all.points());
    std::vector<std::uint8_t> o(all.points());
    for (std::uint64_t i = 0; i < c.size(); ++i) valid_values(i, job.max_bounces, c[i], o[i]);
    write_box(counts, H5T_NATIVE_UINT32, all, c.data());
    write_box(outcomes, H5T_NATIVE_UINT8, all, o.data());
}

// The partial file of an interrupted run (io/partial_file.cpp), every other tile done:
// uncompressed (the tiles in their chunks), or compressed (the tiles' stored chunks past the
// HDF5 objects, where /progress/tile_stored says).
void write_partial(const fs::path& path, const char* text, bool compressed)
{
    Job job = parse_job(text, "template");
    job.compression = compressed ? 4 : 0;
    const Grid grid(job);
    const Tiling tiling(grid.shape(), default_tile_shape(grid.shape(), 48));
    const PartialLayout layout = create_partial(path, job, grid, tiling, template_run);
    std::vector<std::uint8_t> done(tiling.tiles(), 0);
    std::vector<std::uint64_t> sums(tiling.tiles(), 0);
    std::vector<std::uint64_t> stored(3 * tiling.tiles(), 0);
    const auto values_of = [&](std::uint64_t t, std::vector<std::uint32_t>& c, std::vector<std::uint8_t>& o) {
        const Box box = tiling.box(t);
        c.resize(box.points());
        o.resize(box.points());
        for (std::uint64_t i = 0; i < c.size(); ++i) valid_values(t * 1000 + i, job.max_bounces, c[i], o[i]);
    };
    if (compressed) {
        ChunkEncoder encoder(4);
        std::vector<std::byte> bytes;
        std::uint64_t at = fs::file_size(path);
        std::vector<std::uint32_t> c, cc;
        std::vector<std::uint8_t> o, oc;
        for (std::uint64_t t = 0; t < tiling.tiles(); t += 2) {
            values_of(t, c, o);
            const std::size_t from = bytes.size();
            const std::size_t nc = encoder.counts(in_chunk_layout<std::uint32_t>(tiling, t, c, cc), layout.count_bytes, bytes);
            const std::size_t no = encoder.outcomes(in_chunk_layout<std::uint8_t>(tiling, t, o, oc), bytes);
            const std::span<const std::byte> tile(bytes.data() + from, nc + no);
            sums[t] = tile_checksum(t, tile.first(nc), tile.subspan(nc));
            stored[3 * t] = at + from;
            stored[3 * t + 1] = nc;
            stored[3 * t + 2] = no;
            done[t] = 1;
        }
        std::ofstream(path, std::ios::binary | std::ios::app).write(reinterpret_cast<const char*>(bytes.data()),
                                                                    static_cast<std::streamsize>(bytes.size()));
        (void)at;
    }
    {
        PlacedChunks placed(path);  // keeps the bytes appended past HDF5's end
        const hid_t file = placed.file();
        if (!compressed) {
            const h5::Id counts = h5::open_dataset(file, layout::wall_bounces);
            const h5::Id outcomes = h5::open_dataset(file, layout::outcome);
            std::vector<std::uint32_t> c;
            std::vector<std::uint8_t> o;
            for (std::uint64_t t = 0; t < tiling.tiles(); t += 2) {
                values_of(t, c, o);
                write_box(counts, H5T_NATIVE_UINT32, tiling.box(t), c.data());
                write_box(outcomes, H5T_NATIVE_UINT8, tiling.box(t), o.data());
                done[t] = 1;
            }
            h5::check(H5Fflush(file, H5F_SCOPE_GLOBAL), "H5Fflush");
            for (std::uint64_t t = 0; t < tiling.tiles(); t += 2) {
                const std::vector<hsize_t> origin = to_hsize(tiling.box(t).start);
                std::vector<std::byte> chunks[2];
                for (int k = 0; k < 2; ++k) {
                    const hid_t d = k == 0 ? counts.get() : outcomes.get();
                    hsize_t bytes = 0;
                    h5::check(H5Dget_chunk_storage_size(d, origin.data(), &bytes), "H5Dget_chunk_storage_size");
                    chunks[k].resize(bytes);
                    std::uint32_t filters = 0;
                    h5::check(H5Dread_chunk(d, H5P_DEFAULT, origin.data(), &filters, chunks[k].data()), "H5Dread_chunk");
                }
                sums[t] = tile_checksum(t, chunks[0], chunks[1]);
            }
        } else {
            h5::check(H5Dwrite(h5::open_dataset(file, layout::tile_stored), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                               stored.data()),
                      "write tile_stored");
        }
        h5::check(H5Dwrite(h5::open_dataset(file, layout::tile_done), H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                           done.data()),
                  "write tile_done");
        h5::check(H5Dwrite(h5::open_dataset(file, layout::tile_checksum), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                           sums.data()),
                  "write tile_checksum");
        placed.close();
    }
    PlacedChunks::discard_undo(path);
}

fs::path scratch_directory()
{
    std::error_code ec;
    return fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
}

struct Templates {
    fs::path work;
    std::vector<std::string> files;  // each template's bytes

    Templates()
    {
        h5::silence_errors();
        const fs::path dir = scratch_directory();
        const std::string stem = "superball-fuzz-" + std::to_string(::getpid());
        work = dir / (stem + ".h5");
        const fs::path t = dir / (stem + "-template.h5");
        const auto keep = [&] {
            std::ifstream in(t, std::ios::binary);
            files.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
            fs::remove(t);
            fs::remove(layout::partial_path(t));
        };
        write_result(t, job_2d), keep();
        write_partial(t, job_2d, true), keep();
        write_result(t, job_3d), keep();
        write_partial(t, job_1d, false), keep();
        write_partial(t, job_3d, true), keep();
        write_partial(t, job_2d, false), keep();
    }
    ~Templates()
    {
        std::error_code ec;
        fs::remove(work, ec);
    }
};

Templates& templates()
{
    static Templates t;
    return t;
}

// ------------------------------------------------------------------------------ decoding

class Input {
public:
    Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    bool done() const { return at_ >= size_; }
    std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
    std::uint64_t bytes(int n)
    {
        std::uint64_t v = 0;
        for (int i = 0; i < n; ++i) v |= std::uint64_t{byte()} << (8 * i);
        return v;
    }

private:
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t at_ = 0;
};

const std::array<const char*, 8> objects = {"/",     "/wall_bounces",       "/outcome",
                                             "/xi",   "/W",                  "/U",
                                             "/progress/tile_done", "/progress/tile_checksum"};
// The objects of the templates beyond those names: the other coordinate variables.
const std::array<const char*, 5> more_objects = {"/e", "/x", "/u", "/progress", "/progress/tile_stored"};

std::string object_name(Input& in)
{
    const std::uint8_t b = in.byte();
    return b < 200 ? objects[b % objects.size()] : more_objects[b % more_objects.size()];
}

const std::array<const char*, 30> attribute_names = {
    "superball_file", "superball_format", "coordinate_system", "axis_names", "e_wall",   "alpha_wall",
    "e_floor",        "alpha_floor",      "fixed_U",           "fixed_W",    "fixed_xi", "max_bounces",
    "software_version", "job_toml",       "job_fingerprint",   "mpi_ranks",  "wall_seconds", "complete",
    "tile_shape",     "g",                "radius",            "CLASS",      "NAME",     "DIMENSION_LIST",
    "REFERENCE_LIST", "swept",            "fixed_u",           "fixed_v",    "fixed_omega", "coordinates"};

const std::array<const char*, 20> texts = {"result", "partial", "canonical", "physical", "xi", "U", "W", "e", "alpha",
                                           "axis:e", "axis:alpha", "axis:xi", "DIMENSION_SCALE", "", "x", "omega",
                                           "nonsense,,,", "0.1.0", "axis:", "e_wall"};

const std::array<double, 24> numbers = {0, 1, 2, 3, -1, 4, 65535, 65536, 70000, 100, 1000, 4294967295.0, 4294967296.0,
                                        9.2e18, -9.3e18, std::numeric_limits<double>::quiet_NaN(),
                                        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                                        0.5, 1.5, 1e300, -0.25, 255, 256};

double number(Input& in)
{
    const std::uint8_t b = in.byte();
    if (b < 200) return numbers[b % numbers.size()];
    double v = 0;
    const std::uint64_t bits = in.bytes(8);
    std::memcpy(&v, &bits, sizeof v);
    return v;
}

std::string text(Input& in)
{
    const std::uint8_t b = in.byte();
    if (b < 200) return texts[b % texts.size()];
    std::string s(in.byte() % 24, '\0');
    for (char& c : s) c = static_cast<char>(in.byte());
    return s;
}

// The HDF5 type of a value kind: integers of every size and sign, floats, strings.
hid_t numeric_type(std::uint8_t kind)
{
    static const std::array<hid_t, 10> types = {H5T_STD_I64LE, H5T_STD_U8LE, H5T_STD_U64LE, H5T_STD_I8LE, H5T_IEEE_F64LE,
                                                H5T_IEEE_F32LE, H5T_STD_U16BE, H5T_STD_U32LE, H5T_STD_I16LE, H5T_STD_U16LE};
    return types[kind % types.size()];
}

h5::Id string_type(bool variable, std::size_t size)
{
    h5::Id t = h5::type_id(H5Tcopy(H5T_C_S1), "H5Tcopy");
    h5::check(H5Tset_size(t, variable ? H5T_VARIABLE : std::max<std::size_t>(1, size)), "H5Tset_size");
    return t;
}

// --------------------------------------------------------------------------- operations

// Every HDF5 call below may fail on an object the earlier edits removed: the edit is then
// not made (h5::Error), which is no finding.
void set_attribute(hid_t file, Input& in)
{
    const std::string obj = object_name(in);
    const std::uint8_t which = in.byte();
    const h5::Id o = h5::object_id(H5Oopen(file, obj.c_str(), H5P_DEFAULT), "H5Oopen");
    std::string name = attribute_names[which % attribute_names.size()];
    const std::uint8_t kind = in.byte() % 12;
    const std::uint8_t shape = in.byte() % 5;  // scalar, or a list of 1, 2, 3, 5
    const hsize_t n = shape == 0 ? 1 : shape == 4 ? 5 : shape;
    const h5::Id space = shape == 0 ? h5::space_id(H5Screate(H5S_SCALAR), "H5Screate") : h5::simple_space({n});
    if (H5Aexists(o, name.c_str()) > 0) h5::check(H5Adelete(o, name.c_str()), "H5Adelete");
    if (kind < 10) {
        std::vector<double> v(n);
        for (double& x : v) x = number(in);
        const hid_t type = numeric_type(kind);
        const h5::Id a = h5::attribute_id(H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "H5Acreate");
        h5::check(H5Awrite(a, H5T_NATIVE_DOUBLE, v.data()), "H5Awrite");
        return;
    }
    std::vector<std::string> v(n);
    for (std::string& s : v) s = text(in);
    const bool variable = kind == 10;
    std::size_t size = 1;
    for (const std::string& s : v) size = std::max(size, s.size() + 1);
    const h5::Id type = string_type(variable, size);
    const h5::Id a = h5::attribute_id(H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "H5Acreate");
    if (variable) {
        std::vector<const char*> p;
        for (const std::string& s : v) p.push_back(s.c_str());
        h5::check(H5Awrite(a, type, p.data()), "H5Awrite");
    } else {
        std::string buf(n * size, '\0');
        for (hsize_t i = 0; i < n; ++i) std::memcpy(buf.data() + i * size, v[i].data(), v[i].size());
        h5::check(H5Awrite(a, type, buf.data()), "H5Awrite");
    }
}

void delete_attribute(hid_t file, Input& in)
{
    const std::string obj = object_name(in);
    const std::uint8_t which = in.byte();
    const h5::Id o = h5::object_id(H5Oopen(file, obj.c_str(), H5P_DEFAULT), "H5Oopen");
    if (which < 128) {
        h5::check(H5Adelete(o, attribute_names[which % attribute_names.size()]), "H5Adelete");
        return;
    }
    H5O_info_t info{};
    h5::check(H5Oget_info2(o, &info, H5O_INFO_NUM_ATTRS), "H5Oget_info");
    if (info.num_attrs == 0) return;
    h5::check(H5Adelete_by_idx(o, ".", H5_INDEX_NAME, H5_ITER_INC, which % info.num_attrs, H5P_DEFAULT), "H5Adelete_by_idx");
}

void set_value(hid_t file, Input& in)
{
    const std::string obj = object_name(in);
    const h5::Id d = h5::open_dataset(file, obj);
    const h5::Id space = h5::space_id(H5Dget_space(d), "H5Dget_space");
    const hssize_t points = H5Sget_simple_extent_npoints(space);
    if (points <= 0) return;
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
    if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    std::uint64_t i = in.bytes(2) % static_cast<std::uint64_t>(points);
    std::vector<hsize_t> at(dims.size());
    for (std::size_t k = dims.size(); k-- > 0;) {
        at[k] = i % dims[k];
        i /= dims[k];
    }
    const double v = number(in);
    if (rank > 0) h5::check(H5Sselect_elements(space, H5S_SELECT_SET, 1, at.data()), "H5Sselect_elements");
    const h5::Id memory = h5::space_id(H5Screate(H5S_SCALAR), "H5Screate");
    h5::check(H5Dwrite(d, H5T_NATIVE_DOUBLE, memory, space, H5P_DEFAULT, &v), "H5Dwrite");
}

void replace_dataset(hid_t file, Input& in)
{
    const std::string obj = object_name(in);
    const hid_t type = numeric_type(in.byte());
    const int rank = in.byte() % 4;
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    for (hsize_t& n : dims) n = in.byte() % 41;
    const std::uint8_t storage = in.byte() % 3;  // contiguous, chunked, chunked and compressed
    const double base = number(in), step = in.byte() % 4;
    if (h5::object_type(file, obj) != h5::ObjectType::missing) h5::check(H5Ldelete(file, obj.c_str(), H5P_DEFAULT), "H5Ldelete");
    const h5::Id space = rank == 0 ? h5::space_id(H5Screate(H5S_SCALAR), "H5Screate") : h5::simple_space(dims);
    const h5::Id dcpl = h5::plist_id(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
    std::uint64_t points = 1;
    for (const hsize_t n : dims) points *= n;
    if (storage > 0 && rank > 0 && points > 0) {
        std::vector<hsize_t> chunk(dims);
        for (hsize_t& c : chunk) c = std::max<hsize_t>(1, (c + 1) / 2);
        h5::check(H5Pset_chunk(dcpl, rank, chunk.data()), "H5Pset_chunk");
        if (storage == 2) h5::check(H5Pset_deflate(dcpl, 1), "H5Pset_deflate");
    }
    const h5::Id lcpl = h5::plist_id(H5Pcreate(H5P_LINK_CREATE), "H5Pcreate");
    h5::check(H5Pset_create_intermediate_group(lcpl, 1), "H5Pset_create_intermediate_group");
    const h5::Id d = h5::dataset_id(H5Dcreate2(file, obj.c_str(), type, space, lcpl, dcpl, H5P_DEFAULT), "H5Dcreate");
    if (points == 0) return;
    std::vector<double> v(points);
    for (std::uint64_t i = 0; i < points; ++i) v[i] = base + step * static_cast<double>(i);
    h5::check(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "H5Dwrite");
}

void delete_object(hid_t file, Input& in)
{
    const std::string obj = object_name(in);
    if (obj != "/") h5::check(H5Ldelete(file, obj.c_str(), H5P_DEFAULT), "H5Ldelete");
}

// Replaces object a by a second name of object b (two names of one object).
void hard_link(hid_t file, Input& in)
{
    const std::string a = object_name(in), b = object_name(in);
    if (a == "/" || b == "/" || a == b) return;
    h5::check(H5Ldelete(file, a.c_str(), H5P_DEFAULT), "H5Ldelete");
    h5::check(H5Lcreate_hard(file, b.c_str(), file, a.c_str(), H5P_DEFAULT, H5P_DEFAULT), "H5Lcreate_hard");
}

// Where the raw data of every dataset of the file lie: contiguous storage and chunks.
struct Region {
    std::uint64_t offset, size;
};

std::vector<Region> raw_regions(hid_t file)
{
    std::vector<Region> regions;
    std::vector<const char*> names(objects.begin(), objects.end());
    names.insert(names.end(), more_objects.begin(), more_objects.end());
    {
        for (const char* name : names) {
            try {
                if (h5::object_type(file, name) != h5::ObjectType::dataset) continue;
                const h5::Id d = h5::open_dataset(file, name);
                const h5::Id dcpl = h5::plist_id(H5Dget_create_plist(d), "H5Dget_create_plist");
                if (H5Pget_layout(dcpl) == H5D_CHUNKED) {
                    const h5::Id space = h5::space_id(H5Dget_space(d), "H5Dget_space");
                    hsize_t n = 0;
                    h5::check(H5Dget_num_chunks(d, space, &n), "H5Dget_num_chunks");
                    for (hsize_t i = 0; i < n; ++i) {
                        haddr_t at = HADDR_UNDEF;
                        hsize_t size = 0;
                        unsigned mask = 0;
                        if (H5Dget_chunk_info(d, space, i, nullptr, &mask, &at, &size) >= 0 && at != HADDR_UNDEF && size > 0) {
                            regions.push_back({at, size});
                        }
                    }
                } else if (const haddr_t at = H5Dget_offset(d); at != HADDR_UNDEF) {
                    if (const hsize_t size = H5Dget_storage_size(d); size > 0) regions.push_back({at, size});
                }
            } catch (const h5::Error&) {
            }
        }
        // A compressed partial file's stored tiles, past its HDF5 objects.
        try {
            if (h5::object_type(file, layout::tile_stored) == h5::ObjectType::dataset) {
                const h5::Id d = h5::open_dataset(file, layout::tile_stored);
                const h5::Shape st = h5::dataset_shape_of(d);
                if (st.dims.size() == 2 && st.dims[1] == 3 && st.bytes == 8 && st.dims[0] < 4096) {
                    std::vector<std::uint64_t> w(3 * st.dims[0]);
                    h5::check(H5Dread(d, H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, w.data()), "read");
                    for (std::size_t t = 0; t < st.dims[0]; ++t) {
                        if (w[3 * t + 1] + w[3 * t + 2] > 0 && w[3 * t + 1] + w[3 * t + 2] < (1u << 20)) {
                            regions.push_back({w[3 * t], w[3 * t + 1] + w[3 * t + 2]});
                        }
                    }
                }
            }
        } catch (const h5::Error&) {
        }
    }
    return regions;
}

// Applies the edits of `in` to the file at `path`.
void edit(const fs::path& path, Input& in)
{
    std::vector<Region> regions;
    {
        h5::Id file;
        try {
            file = h5::open_file(path, true);
        } catch (const h5::Error&) {
            return;
        }
        bool raw = false;
        while (!in.done() && !raw) {
            try {
                switch (in.byte() % 8) {
                    case 0: delete_attribute(file, in); break;
                    case 1: set_attribute(file, in); break;
                    case 2: set_value(file, in); break;
                    case 3: replace_dataset(file, in); break;
                    case 4: delete_object(file, in); break;
                    case 5: hard_link(file, in); break;
                    case 6: raw = true; break;
                    default: break;
                }
            } catch (const h5::Error&) {
            }
        }
        if (!raw) return;
        if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) return;
        regions = raw_regions(file);
    }
    if (regions.empty()) return;
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return;
    while (!in.done()) {
        const Region& r = regions[in.byte() % regions.size()];
        const std::uint64_t at = r.offset + in.bytes(2) % r.size;
        const std::size_t n = std::min<std::uint64_t>(in.byte() % 8 + 1, r.offset + r.size - at);
        unsigned char buf[8];
        for (std::size_t i = 0; i < n; ++i) buf[i] = in.byte();
        if (::pwrite(fd, buf, n, static_cast<off_t>(at)) < 0) break;
    }
    ::close(fd);
}

// ------------------------------------------------------------------------------ reading

void read_all(const fs::path& path, std::uint64_t seed)
{
    const ResultReader reader(path);
    const ResultInfo& info = reader.info();
    require(info.axis_names.size() == info.shape.size() && !info.shape.empty() && info.shape.size() <= 4, "axes");
    require(info.max_bounces >= 1, "max_bounces >= 1");
    require(info.tiles_done <= info.tiles, "tiles done <= tiles");
    require(info.kind == FileKind::result ? info.complete : !info.complete, "complete iff a result");
    for (std::size_t k = 0; k < info.shape.size(); ++k) {
        const std::vector<double> a = reader.axis(k);
        require(a.size() == info.shape[k], "axis length");
        for (std::size_t i = 1; i < a.size(); ++i) require(a[i] > a[i - 1], "increasing axis");
    }
    // A box chosen by the input.
    Box box{Extent(info.shape.size()), Extent(info.shape.size())};
    for (std::size_t k = 0; k < info.shape.size(); ++k) {
        box.start[k] = (seed >> (8 * k)) % info.shape[k];
        box.count[k] = 1 + (seed >> (8 * k + 4)) % (info.shape[k] - box.start[k]);
    }
    std::vector<std::uint32_t> counts(box.points());
    std::vector<std::uint8_t> outcomes(box.points());
    const std::uint64_t missing = reader.read(box, counts, outcomes);
    require(missing <= box.points(), "missing <= points");
    for (std::size_t i = 0; i < counts.size(); ++i) {
        require(outcomes[i] <= 3, "outcome code 0-3");
        require(outcomes[i] == 0 ? counts[i] == 0
                : outcomes[i] == 3 ? counts[i] == info.max_bounces
                                   : counts[i] <= info.max_bounces,
                "count allowed by its outcome");
    }
    const OutcomeCounts h = reader.outcome_counts();
    std::uint64_t sum = h.not_computed;
    for (const std::uint64_t n : h.by_outcome) sum += n;
    require(sum == info.points(), "every point counted once");
    require(reader.damaged_tiles().empty(), "tiles read intact");
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    templates();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    Templates& t = templates();
    Input in(data, size);
    const std::string& file = t.files[in.byte() % t.files.size()];
    {
        std::ofstream out(t.work, std::ios::binary | std::ios::trunc);
        out.write(file.data(), static_cast<std::streamsize>(file.size()));
    }
    edit(t.work, in);
    std::uint64_t seed = 0x9e3779b97f4a7c15;
    for (std::size_t i = 0; i < size; ++i) seed = (seed ^ data[i]) * 0x100000001b3;
    try {
        read_all(t.work, seed);
    } catch (const InputError&) {
        // The one accepted way to refuse a file (FormatError is one).
    }
    (void)identify_file(t.work);
    // Anything else propagates: libFuzzer reports an uncaught exception as a crash.
    return 0;
}
