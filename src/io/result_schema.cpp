// The reader's checks of a file's structure at open (ResultReader::validate and its parts):
// which objects, types, shapes and attributes a result or partial file has, and how they
// agree. Each part reads what the ones before it validated.
#include "result_schema.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <tuple>
#include <set>
#include <system_error>

#include "job/job.hpp"
#include "chunk_codec.hpp"
#include "file_identity.hpp"
#include "hdf5.hpp"
#include "layout.hpp"
#include "stored_tiles.hpp"

namespace superball {

namespace fs = std::filesystem;
namespace attr = layout::attr;

namespace schema {

std::string dims_text(const std::vector<hsize_t>& dims)
{
    return dims.empty() ? "a scalar" : fmt::format("({})", fmt::join(dims, ", "));
}

std::string shape_text(const h5::Shape& s)
{
    const char* kind = "value of another type";
    switch (s.type) {
        case h5::TypeClass::string: kind = "text"; break;
        case h5::TypeClass::integer: kind = "integer"; break;
        case h5::TypeClass::floating: kind = "floating-point number"; break;
        case h5::TypeClass::other: break;
    }
    if (s.scalar) return fmt::format("{} {}", s.type == h5::TypeClass::integer ? "an" : "a", kind);
    if (s.elements() == 0) return "empty";
    if (s.dims.size() == 1) return fmt::format("a list of {} {}s", s.dims[0], kind);
    return fmt::format("an array {} of {}s", dims_text(s.dims), kind);
}

h5::Id open_hdf5(const fs::path& path)
{
    // Failures are reported as FormatError and h5::Error, each saying what failed: HDF5's
    // own printout of its error stack would only add noise on stderr.
    h5::silence_errors();
    const std::string p = path.string();
    std::error_code ec;
    if (!fs::exists(path, ec)) throw FormatError(p + ": no such file");
    if (!fs::is_regular_file(path, ec)) throw FormatError(p + " is " + describe_file(path) + ", not a superball file");
    if (!h5::is_hdf5(path)) throw FormatError(p + " is " + describe_file(path) + ", not a superball result");
    try {
        return h5::open_file(path, false);
    } catch (const h5::Error& e) {
        throw FormatError(p + " is an HDF5 file that cannot be opened, damaged or truncated (" + e.what() + ")");
    }
}

// The byte ranges of the file's big raw data, which damaged_global_heap need not search:
// contiguous datasets, chunked ones without filters whose chunks lie one after the other
// (an uncompressed partial file's), and the tiles a compressed partial file records done.
// Whatever cannot be told is searched.
std::vector<std::pair<std::uint64_t, std::uint64_t>> raw_data_ranges(hid_t file)
{
    std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges;
    try {
        if (h5::object_type(file, layout::tile_stored) == h5::ObjectType::dataset &&
            h5::object_type(file, layout::tile_done) == h5::ObjectType::dataset) {
            const h5::Id done_set = h5::open_dataset(file, layout::tile_done);
            const h5::Id stored_set = h5::open_dataset(file, layout::tile_stored);
            const h5::Shape ds = h5::dataset_shape_of(done_set), ss = h5::dataset_shape_of(stored_set);
            if (ds.dims.size() == 1 && ds.bytes == 1 && ss.bytes == 8 && ss.dims == std::vector<hsize_t>{ds.dims[0], 3} &&
                ds.dims[0] <= max_grid_points) {
                // A window of tiles at a time, the ranges merged as they come (appended
                // tiles lie one after the other): neither the journal nor a range a tile is
                // held at once (41 bytes a tile, 170 MiB at 4 million tiles).
                std::map<std::uint64_t, std::uint64_t> merged;  // begin -> end, disjoint
                const auto add = [&](std::uint64_t begin, std::uint64_t end) {
                    auto it = merged.upper_bound(begin);
                    if (it != merged.begin() && std::prev(it)->second >= begin) {
                        --it;
                        begin = it->first;
                        end = std::max(end, it->second);
                        it = merged.erase(it);
                    }
                    while (it != merged.end() && it->first <= end) {
                        end = std::max(end, it->second);
                        it = merged.erase(it);
                    }
                    merged.emplace(begin, end);
                };
                constexpr hsize_t window = 65536;
                std::vector<std::uint64_t> done, stored;
                for (hsize_t first = 0; first < ds.dims[0]; first += window) {
                    const hsize_t n = std::min(window, ds.dims[0] - first);
                    done.resize(n);
                    stored.resize(3 * n);
                    h5::read_rows(done_set, first, n, done, layout::tile_done);
                    h5::read_rows(stored_set, first, n, stored, layout::tile_stored);
                    for (std::size_t t = 0; t < n; ++t) {
                        if (done[t] == 1) add(stored[3 * t], stored[3 * t] + stored[3 * t + 1] + stored[3 * t + 2]);
                    }
                }
                for (const auto& [begin, end] : merged) ranges.emplace_back(begin, end - begin);
            }
        }
    } catch (const h5::Error&) {
    }
    for (const char* name : {layout::wall_bounces, layout::outcome, layout::tile_done, layout::tile_checksum, layout::tile_stored}) {
        try {
            if (h5::object_type(file, name) != h5::ObjectType::dataset) continue;
            const h5::Id d = h5::open_dataset(file, name);
            const h5::Shape s = h5::dataset_shape_of(d);
            const h5::Storage st = h5::dataset_storage(d);
            if (st.chunk.empty()) {
                if (const auto range = h5::contiguous_range(d)) ranges.push_back(*range);
                continue;
            }
            // (A result's compressed chunks are searched: HDF5 1.10 finds a chunk's address by
            // walking its whole index, so listing them costs the square of their number.)
            if (st.filters != 0 || !st.allocated || s.elements() == 0) continue;
            std::uint64_t chunk_bytes = s.bytes, chunks = 1;
            std::vector<hsize_t> last(s.dims.size());
            for (std::size_t k = 0; k < s.dims.size(); ++k) {
                chunk_bytes *= st.chunk[k];
                chunks *= (s.dims[k] + st.chunk[k] - 1) / st.chunk[k];
                last[k] = (s.dims[k] - 1) / st.chunk[k] * st.chunk[k];
            }
            const std::uint64_t first_at = h5::chunk_offset(d, std::vector<hsize_t>(s.dims.size(), 0));
            if (h5::chunk_offset(d, last) == first_at + (chunks - 1) * chunk_bytes) {
                ranges.emplace_back(first_at, chunks * chunk_bytes);
            }
        } catch (const h5::Error&) {
        }
    }
    return ranges;
}

}  // namespace schema

using namespace schema;

namespace {

bool is_coefficient(const std::string& n)
{
    static const std::vector<std::string> names = coefficient_names();
    return std::find(names.begin(), names.end(), n) != names.end();
}

// Whether coefficient attribute `key` (e_wall, ...) may be swept by the axis `axis`: its
// own name, or the shorthand of its kind (e, alpha) that sets both surfaces.
bool sweeps(std::string_view axis, std::string_view key) { return axis == key || axis == key.substr(0, key.find('_')); }

// Names of the coordinates of a coordinate system, in result order.
std::vector<std::string> coordinates_of(const std::string& system)
{
    if (system == "canonical") return {"xi", "U", "W"};
    return {"x", "u", "v", "omega"};
}

}  // namespace

// Each part reads what the ones before it validated.
void ResultReader::validate()
{
    validate_kind();
    validate_axes();
    validate_job_and_model();
    validate_no_journal();
    validate_data();
    validate_coordinates();
    if (info_.kind == FileKind::partial) validate_partial();
}

// What the file is: a superball result or partial file of a format this version reads.
void ResultReader::validate_kind()
{
    const Checker check(file_, path_);
    ResultInfo& in = info_;

    // Before any text is read: HDF5 reads variable-length values without checking them.
    if (const std::optional<std::uint64_t> at = h5::damaged_global_heap(path_, raw_data_ranges(file_))) {
        check.fail(fmt::format("the global heap at byte {} (where HDF5 keeps texts and dimension-scale lists) is damaged: "
                               "its objects do not fit it",
                               *at));
    }

    // What the file is.
    if (!h5::has_attribute(file_, layout::kind_attribute)) {
        // Attributes only this layout has: the file is of this layout, damaged.
        if (h5::has_attribute(file_, attr::format) || h5::has_attribute(file_, attr::coordinate_system)) {
            check.fail("attribute " + std::string(layout::kind_attribute) + " is missing");
        }
        if (h5::has_attribute(file_, attr::job_toml) && h5::has_attribute(file_, attr::software_version)) {
            std::string version = "?";
            try {
                version = h5::read_string_attribute(file_, attr::software_version);
            } catch (const h5::Error&) {
            }
            check.fail("written by superball " + printable(version) +
                       " in the layout before netCDF conventions, which this version does not read; run the job again "
                       "with this version");
        }
        check.fail("an HDF5 file that is not a superball result (no attribute " + std::string(layout::kind_attribute) + ")");
    }
    const std::string kind = check.text(layout::kind_attribute);
    if (kind != layout::kind_result && kind != layout::kind_partial) {
        check.fail(fmt::format("attribute {} = \"{}\" is neither \"{}\" nor \"{}\"", layout::kind_attribute, printable(kind),
                               layout::kind_result, layout::kind_partial));
    }
    in.kind = kind == layout::kind_result ? FileKind::result : FileKind::partial;
    if (const std::int64_t format = check.integer(attr::format, 0, std::numeric_limits<std::int64_t>::max());
        format != layout::format_version && !(in.kind == FileKind::result && format >= layout::oldest_result_format &&
                                              format < layout::format_version)) {
        check.fail(in.kind == FileKind::result
                       ? fmt::format("attribute {format_attr} = {}: this version of superball reads results of format {} "
                                     "to {}; read the file with the version that wrote it",
                                     format, layout::oldest_result_format, layout::format_version,
                                     fmt::arg("format_attr", attr::format.name))
                       : fmt::format("attribute {format_attr} = {}: a partial file of format {} is resumed by the version "
                                     "that wrote it, this one resumes format {} only",
                                     format, format, layout::format_version, fmt::arg("format_attr", attr::format.name)));
    }
}

// The grid's coordinates and axes: which are ranges (axis_names, in order), which are fixed.
void ResultReader::validate_axes()
{
    const Checker check(file_, path_);
    ResultInfo& in = info_;
    in.coordinate_system = check.text(attr::coordinate_system);
    if (in.coordinate_system != "canonical" && in.coordinate_system != "physical") {
        check.fail(fmt::format("attribute {} = \"{}\" is neither canonical nor physical", attr::coordinate_system.name,
                               printable(in.coordinate_system)));
    }
    const std::vector<std::string> coordinates = coordinates_of(in.coordinate_system);
    in.axis_names = check.texts(attr::axis_names, 4);
    std::set<std::string> seen;
    std::ptrdiff_t last_coordinate = -1;
    for (const std::string& a : in.axis_names) {
        const auto c = std::find(coordinates.begin(), coordinates.end(), a);
        if (c == coordinates.end() && !is_coefficient(a)) {
            check.fail(fmt::format("attribute {axis_names_attr} names \"{}\", which is neither a {} coordinate ({}) nor a model "
                                   "coefficient ({})",
                                   printable(a), in.coordinate_system, fmt::join(coordinates, ", "),
                                   fmt::join(coefficient_names(), ", "),
                                   fmt::arg("axis_names_attr", attr::axis_names.name)));
        }
        if (!seen.insert(a).second) check.fail(fmt::format("attribute {} names \"{}\" twice", attr::axis_names.name, a));
        // Swept coefficients first, then the coordinates in their order (as written).
        const std::ptrdiff_t order = c == coordinates.end() ? -1 : c - coordinates.begin();
        if (order < last_coordinate) {
            check.fail(fmt::format("attribute {axis_names_attr} lists ({}) out of order: swept coefficients first, then {}",
                                   fmt::join(printable(in.axis_names), ", "), fmt::join(coordinates, ", "),
                                   fmt::arg("axis_names_attr", attr::axis_names.name)));
        }
        last_coordinate = std::max(last_coordinate, order);
    }
    for (const std::string& c : coordinates) {
        if (std::find(in.axis_names.begin(), in.axis_names.end(), c) == in.axis_names.end()) {
            in.fixed.emplace_back(c, check.number(attr::fixed_prefix + c));
        }
    }
    if (in.fixed.size() + 3 < coordinates.size()) {
        check.fail(fmt::format("attribute {axis_names_attr} lists {} {} coordinates: a grid has at most 3 ranges",
                               coordinates.size() - in.fixed.size(), in.coordinate_system,
                               fmt::arg("axis_names_attr", attr::axis_names.name)));
    }
}

// The job, the run, the provenance and the model's coefficients.
void ResultReader::validate_job_and_model()
{
    const Checker check(file_, path_);
    ResultInfo& in = info_;
    in.max_bounces = check.integer(attr::max_bounces, 1, max_max_bounces);
    in.software_version = check.text(attr::software_version);
    in.job_toml = check.text(attr::job_toml, max_job_bytes);
    // The job is printed and resumed from: a damaged text (its bytes sit in HDF5's global
    // heap, which has no checksum) is refused, not shown.
    try {
        parse_job(in.job_toml, attr::job_toml.name);
    } catch (const InputError& e) {
        check.fail(fmt::format("attribute {job_toml_attr} is not the text of a valid job ({}): the file is damaged",
                               printable(e.what()), fmt::arg("job_toml_attr", attr::job_toml.name)));
    }
    in.job_fingerprint = check.text(attr::job_fingerprint, max_job_bytes);
    in.mpi_ranks = check.integer(attr::mpi_ranks, 0, std::int64_t{1} << 40);
    // Provenance, in files of superball 0.1.0 from commit-recording builds on: optional.
    // Printed by info as they are: damaged bytes are refused, not shown.
    const auto optional_text = [&](const char* key, std::size_t max_bytes) {
        if (!h5::has_attribute(file_, key)) return std::string();
        std::string v = check.text(key, max_bytes);
        if (!printable_lines(v)) check.fail(fmt::format("attribute {} = \"{}\" is not UTF-8 text: the file is damaged", key, printable(v)));
        return v;
    };
    in.history = optional_text(attr::history.name, max_job_bytes);
    in.source = optional_text(attr::source.name, max_text_bytes);
    in.date_created = optional_text(attr::date_created.name, max_text_bytes);
    in.build = optional_text(attr::build.name, max_text_bytes);
    if (h5::has_attribute(file_, attr::mpi_hosts)) in.mpi_hosts = check.integer(attr::mpi_hosts, 1, std::int64_t{1} << 40);
    if (h5::has_attribute(file_, attr::threads)) in.threads = check.integer(attr::threads, 1, std::int64_t{1} << 20);
    in.wall_seconds = check.number(attr::wall_seconds);
    if (in.wall_seconds < 0) check.fail(fmt::format("attribute {wall_seconds_attr} = {} is negative", in.wall_seconds,
                                                    fmt::arg("wall_seconds_attr", attr::wall_seconds.name)));
    in.complete = check.integer(attr::complete, 0, 1) == 1;
    if (in.kind == FileKind::result && !in.complete) {
        check.fail(fmt::format("attribute {} = 0 contradicts {} = result (a result is written {complete_attr})", attr::complete.name,
                               attr::kind.name, fmt::arg("complete_attr", attr::complete.name)));
    }
    if (in.kind == FileKind::partial && in.complete) {
        check.fail(fmt::format("attribute {} = 1 contradicts {} = partial (a run in progress)", attr::complete.name,
                               attr::kind.name));
    }
    // A coefficient is a number in its range, or names the axis that sweeps it.
    std::set<std::string> swept;
    for (const std::string& name : model_coefficient_names()) {
        const char* const key = name.c_str();
        // Files written before SPEC.md 1b have no mu_wall, mu_floor, inertia: the Cross model
        // of a solid ball.
        if (is_friction_coefficient(name) && !h5::has_attribute(file_, key)) continue;
        const std::optional<h5::Shape> s = h5::attribute_shape(file_, key);
        if (s && s->type == h5::TypeClass::string) {
            const std::string v = check.text(key);
            const std::string axis = v.rfind("axis:", 0) == 0 ? v.substr(5) : "";
            if (std::find(in.axis_names.begin(), in.axis_names.end(), axis) == in.axis_names.end() || !sweeps(axis, key)) {
                check.fail(fmt::format("attribute {} = \"{}\" names no axis of the file that sweeps {}", key, printable(v), key));
            }
            swept.insert(axis);
            continue;
        }
        const double v = check.number(key);
        if (!coefficient_in_range(name, v)) {
            check.fail(fmt::format("attribute {} = {} is out of range: accepted {}", key, v, coefficient_range_text(name)));
        }
    }
    for (const std::string& a : in.axis_names) {
        if (is_coefficient(a) && !swept.count(a)) {
            check.fail(fmt::format("attribute {axis_names_attr} names the coefficient {0}, but no coefficient attribute says "
                                   "\"axis:{0}\"",
                                   a, fmt::arg("axis_names_attr", attr::axis_names.name)));
        }
    }
    if (in.coordinate_system == "physical") {
        for (const char* key : {attr::g.name, attr::radius.name}) {
            if (const double v = check.number(key); !(v > 0)) {
                check.fail(fmt::format("attribute {} = {} is out of range: accepted > 0", key, v));
            }
        }
    }
}

// A result is complete: a resume journal belongs to a run in progress.
void ResultReader::validate_no_journal()
{
    const Checker check(file_, path_);
    const ResultInfo& in = info_;
    if (in.kind == FileKind::result && h5::object_type(file_, "/progress") != h5::ObjectType::missing) {
        std::string journal;
        if (h5::object_type(file_, layout::tile_done) == h5::ObjectType::dataset) {
            const h5::Id d = h5::open_dataset(file_, layout::tile_done);
            const h5::Shape s = h5::dataset_shape_of(d);
            if (s.type == h5::TypeClass::integer && s.bytes == 1 && s.dims.size() == 1 && s.dims[0] <= max_grid_points &&
                h5::dataset_storage(d).allocated) {
                std::vector<std::uint8_t> flags(s.dims[0]);
                h5::read(d, std::span(flags), layout::tile_done);
                journal = fmt::format(", /progress/tile_done, recording {} of {} tiles done", std::count(flags.begin(), flags.end(), 1),
                                      flags.size());
            }
        }
        check.fail(fmt::format("{kind_attr} = result and {complete_attr} = 1 say the run is {complete_attr}, but the file holds a resume "
                               "journal{}: the file contradicts itself",
                               journal.empty() ? " (/progress), which only a run in progress has" : journal,
                               fmt::arg("complete_attr", attr::complete.name), fmt::arg("kind_attr", attr::kind.name)));
    }
}

// The data: types, shapes agreeing with the axes, storage.
void ResultReader::validate_data()
{
    const Checker check(file_, path_);
    ResultInfo& in = info_;
    counts_ = check.dataset(layout::wall_bounces);
    outcomes_ = check.dataset(layout::outcome);
    const h5::Shape cs = h5::dataset_shape_of(counts_);
    const h5::Shape os = h5::dataset_shape_of(outcomes_);
    // A partial file's bytes are written and checksummed as they lie in memory: little-endian.
    const bool any_order = in.kind == FileKind::result;
    if (cs.type != h5::TypeClass::integer || cs.is_signed || (cs.bytes != 2 && cs.bytes != 4) ||
        !(any_order || cs.little_endian)) {
        check.fail(fmt::format("/wall_bounces holds {}{}: accepted unsigned 16- or 32-bit integers{}", shape_text(cs),
                               cs.type == h5::TypeClass::integer
                                   ? fmt::format(" of {} bits, {}", 8 * cs.bytes, cs.is_signed ? "signed" : "unsigned")
                                   : "",
                               any_order ? "" : " (little-endian)"));
    }
    if (os.type != h5::TypeClass::integer || os.is_signed || os.bytes != 1) {
        check.fail(fmt::format("/outcome holds {}{}: accepted unsigned 8-bit integers", shape_text(os),
                               os.type == h5::TypeClass::integer
                                   ? fmt::format(" of {} bits, {}", 8 * os.bytes, os.is_signed ? "signed" : "unsigned")
                                   : ""));
    }
    if (cs.scalar || cs.dims.size() != in.axis_names.size()) {
        check.fail(fmt::format("/wall_bounces has {} dimensions {} but {axis_names_attr} lists {} axes ({})", cs.dims.size(),
                               dims_text(cs.dims), in.axis_names.size(), fmt::join(in.axis_names, ", "),
                               fmt::arg("axis_names_attr", attr::axis_names.name)));
    }
    if (os.scalar || os.dims != cs.dims) {
        check.fail("/outcome " + dims_text(os.dims) + " and /wall_bounces " + dims_text(cs.dims) + " differ in shape");
    }
    std::uint64_t points = 1;
    for (const hsize_t n : cs.dims) {
        if (n == 0) check.fail("/wall_bounces " + dims_text(cs.dims) + " is empty");
        if (__builtin_mul_overflow(points, n, &points) || points > max_grid_points) {
            check.fail(fmt::format("/wall_bounces {} has more than 2^40 points", dims_text(cs.dims)));
        }
    }
    in.shape.assign(cs.dims.begin(), cs.dims.end());
    in.count_bytes = cs.bytes;
    if (in.max_bounces > 65535 && in.count_bytes == 2) {
        check.fail(fmt::format("max_bounces = {} does not fit the 16-bit counts of /wall_bounces", in.max_bounces));
    }
    // A compressed partial file's chunks are indexed when it becomes the result.
    if (in.kind == FileKind::result) {
        check.allocated(counts_, layout::wall_bounces);
        check.allocated(outcomes_, layout::outcome);
    }
}

// Coordinate variables: each axis's samples, a dimension scale attached to its dimension of
// both datasets (what xarray and netCDF tools read as its coordinate); each fixed coordinate
// a scalar variable agreeing with its attribute.
void ResultReader::validate_coordinates()
{
    const Checker check(file_, path_);
    const ResultInfo& in = info_;
    const auto attached = [&](hid_t data, const char* data_name) {
        std::vector<std::vector<haddr_t>> scales;
        try {
            scales = h5::attached_scales(data);
        } catch (const h5::Error& e) {
            check.fail(std::string(data_name) + ": " + e.what());
        }
        if (scales.size() != in.axis_names.size()) {
            check.fail(fmt::format("{} has {} dimension scales attached (attribute DIMENSION_LIST) for its {} dimensions",
                                   data_name, scales.size(), in.axis_names.size()));
        }
        return scales;
    };
    const std::vector<std::vector<haddr_t>> count_scales = attached(counts_, layout::wall_bounces);
    const std::vector<std::vector<haddr_t>> outcome_scales = attached(outcomes_, layout::outcome);
    for (std::size_t k = 0; k < in.axis_names.size(); ++k) {
        axis(k);
        const std::string name = "/" + in.axis_names[k];
        const h5::Id d = h5::open_dataset(file_, name);
        const std::optional<h5::Shape> cls = h5::attribute_shape(d, "CLASS");
        if (!cls || cls->type != h5::TypeClass::string || !cls->scalar || cls->bytes > 64 ||
            h5::read_string_attribute(d, "CLASS") != "DIMENSION_SCALE") {
            check.fail(name + " is not a dimension scale (its attribute CLASS is not \"DIMENSION_SCALE\")");
        }
        const haddr_t at = h5::object_address(d);
        for (const auto& [scales, data_name] : {std::pair{&count_scales, layout::wall_bounces},
                                                std::pair{&outcome_scales, layout::outcome}}) {
            const std::vector<haddr_t>& s = (*scales)[k];
            if (std::find(s.begin(), s.end(), at) == s.end()) {
                check.fail(fmt::format("{} is not attached to dimension {} of {}, which {axis_names_attr} says is {}", name, k,
                                       data_name, in.axis_names[k], fmt::arg("axis_names_attr", attr::axis_names.name)));
            }
        }
    }
    // Fixed coordinates: scalar variables agreeing with the attributes.
    for (const auto& [name, value] : in.fixed) {
        const std::string v = "/" + name;
        const h5::Id d = check.dataset(v);
        const h5::Shape s = h5::dataset_shape_of(d);
        if (s.type != h5::TypeClass::floating || !s.scalar) {
            check.fail(fmt::format("{} holds {}, not one floating-point number (the fixed coordinate {})", v, shape_text(s),
                                   name));
        }
        check.allocated(d, v);
        double x = 0;
        h5::read(d, std::span(&x, 1), v);
        if (!(x == value)) check.fail(fmt::format("{} = {} contradicts attribute {}{} = {}", v, x, attr::fixed_prefix, name, value));
    }
}

// A partial file: its tiles, their storage, then the resume journal.
void ResultReader::validate_partial()
{
    validate_tiles();
    validate_journal();
}

void ResultReader::validate_tiles()
{
    const Checker check(file_, path_);
    ResultInfo& in = info_;
    in.tile_shape = check.integers(attr::tile_shape, in.shape.size());
    for (std::size_t k = 0; k < in.shape.size(); ++k) {
        if (in.tile_shape[k] < 1 || in.tile_shape[k] > in.shape[k]) {
            check.fail(fmt::format("attribute {tile_shape_attr} = ({}) does not fit the data ({})", fmt::join(in.tile_shape, ", "),
                                   fmt::join(in.shape, ", "), fmt::arg("tile_shape_attr", attr::tile_shape.name)));
        }
    }
    tiling_.emplace(in.shape, in.tile_shape);
    in.tiles = tiling_->tiles();
    // One chunk per tile: uncompressed, each tile's bytes written straight to its chunk;
    // compressed, shuffle + deflate as in the result, the chunks appended past the HDF5
    // objects (listed in /progress/tile_stored) and not indexed yet.
    const h5::Storage counts_storage = h5::dataset_storage(counts_);
    compressed_ = counts_storage.filters != 0;
    for (const auto& [d, name] : {std::pair{counts_.get(), layout::wall_bounces}, std::pair{outcomes_.get(), layout::outcome}}) {
        const h5::Storage st = h5::dataset_storage(d);
        const bool as_counts = st.filters == counts_storage.filters && st.shuffle == counts_storage.shuffle &&
                               st.deflate_level == counts_storage.deflate_level;
        const bool pipeline = compressed_ ? st.filters == 2 && st.shuffle && st.deflate_level >= 1 && st.deflate_level <= 9
                                          : st.filters == 0;
        if (st.chunk != std::vector<hsize_t>(in.tile_shape.begin(), in.tile_shape.end()) || !pipeline || !as_counts) {
            check.fail(fmt::format("{} is stored {}{}, not in chunks of {tile_shape_attr} ({}), uncompressed or through shuffle and "
                                   "deflate alike for both datasets, as a partial file is",
                                   name, st.chunk.empty() ? "unchunked" : "in chunks of " + dims_text(st.chunk),
                                   st.filters ? fmt::format(" through {} filters", st.filters) : "",
                                   fmt::join(in.tile_shape, ", "), fmt::arg("tile_shape_attr", attr::tile_shape.name)));
        }
        if (!compressed_) {
            check.allocated(d, name);
        } else {
            if (const std::uint64_t chunks = h5::allocated_chunks(d); chunks != 0) {
                check.fail(fmt::format("{} holds chunks ({}), which a compressed partial file never does: its tiles are "
                                       "in /progress/tile_stored until the run completes; the file is damaged",
                                       name, chunks));
            }
        }
    }
}

// The journal: which tiles are done, their checksums and (compressed) where their chunks lie.
void ResultReader::validate_journal()
{
    const Checker check(file_, path_);
    ResultInfo& in = info_;
    std::vector<const char*> journal{layout::tile_done, layout::tile_checksum};
    if (compressed_) journal.push_back(layout::tile_stored);
    for (const char* name : journal) {
        const h5::Id d = check.dataset(name);
        const h5::Shape s = h5::dataset_shape_of(d);
        const std::size_t bytes = name == layout::tile_done ? 1 : 8;
        const std::vector<hsize_t> dims = name == layout::tile_stored ? std::vector<hsize_t>{in.tiles, 3} : std::vector<hsize_t>{in.tiles};
        if (s.type != h5::TypeClass::integer || s.is_signed || s.bytes != bytes || !s.little_endian || s.dims != dims) {
            check.fail(fmt::format("{} holds {} but {tile_shape_attr} ({}) makes {} tiles: accepted {} unsigned {}-bit integers",
                                   name, shape_text(s), fmt::join(in.tile_shape, ", "), in.tiles, dims_text(dims), 8 * bytes,
                                   fmt::arg("tile_shape_attr", attr::tile_shape.name)));
        }
        check.allocated(d, name);
    }
    done_.resize(in.tiles);
    h5::read(h5::open_dataset(file_, layout::tile_done), std::span(done_), layout::tile_done);
    for (std::uint64_t t = 0; t < in.tiles; ++t) {
        if (done_[t] > 1) check.fail(fmt::format("{} holds {} for tile {}: accepted 0 or 1", layout::tile_done, done_[t], t));
    }
    if (compressed_) {
        // Checked a window of tiles at a time and not kept: a run resuming from this file
        // needs only the flags (24 bytes a tile is 100 MiB at 4 million tiles).
        const h5::Id stored_set = h5::open_dataset(file_, layout::tile_stored);
        const std::uint64_t size = fs::file_size(path_);
        // A stored chunk inflates to at most 1032 times its size (deflate's limit); a
        // tile's are never empty.
        const std::uint64_t chunk_bytes = tiling_->tile_points() * in.count_bytes;
        constexpr std::uint64_t window = 65536;
        std::vector<std::uint64_t> words;
        for (std::uint64_t first = 0; first < in.tiles; first += window) {
            const std::uint64_t n = std::min(window, in.tiles - first);
            words.resize(3 * n);
            h5::read_rows(stored_set, first, n, words, layout::tile_stored);
            for (std::uint64_t i = 0; i < n; ++i) {
                const std::uint64_t t = first + i;
                const StoredChunk c{words[3 * i], words[3 * i + 1], words[3 * i + 2]};
                if (done_[t] == 0) continue;
                if (c.counts_bytes == 0 || c.outcomes_bytes == 0 || c.counts_bytes > chunk_bytes + chunk_bytes / 2 + 64 ||
                    c.outcomes_bytes > chunk_bytes || c.address > size || c.end() > size || c.end() < c.address) {
                    check.fail(fmt::format("{} places done tile {} at bytes {} to {} (+{}), which a file of {} bytes "
                                           "cannot hold: the file is truncated or damaged",
                                           layout::tile_stored, t, c.address, c.address + c.counts_bytes, c.outcomes_bytes,
                                           size));
                }
            }
        }
    }
    in.tiles_done = static_cast<std::uint64_t>(std::count(done_.begin(), done_.end(), std::uint8_t{1}));
    verified_.assign(in.tiles, 0);
}

}  // namespace superball
