#include "result_reader.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <system_error>

#include "layout.hpp"
#include "partial_file.hpp"

namespace superball {

namespace fs = std::filesystem;

namespace {

constexpr std::int64_t max_max_bounces = 4294967295;

std::vector<hsize_t> to_hsize(const Extent& e) { return {e.begin(), e.end()}; }

std::string dims_text(const std::vector<hsize_t>& dims)
{
    return dims.empty() ? "a scalar" : fmt::format("({})", fmt::join(dims, ", "));
}

bool is_coefficient(std::string_view n)
{
    return n == "e" || n == "alpha" || n == "e_wall" || n == "alpha_wall" || n == "e_floor" || n == "alpha_floor";
}

// Names of the coordinates of a coordinate system, in result order.
std::vector<std::string> coordinates_of(const std::string& system)
{
    if (system == "canonical") return {"xi", "U", "W"};
    return {"x", "u", "v", "omega"};
}

class Checker {
public:
    Checker(hid_t file, const fs::path& path) : file_(file), path_(path.string()) {}

    [[noreturn]] void fail(const std::string& what) const { throw FormatError(path_ + ": " + what); }

    // Root attributes of the kinds the format uses, each checked for its type and shape.
    std::string text(const std::string& name) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::string || s.elements() != 1) fail("attribute " + name + " is not a text");
        return h5::read_string_attribute(file_, name);
    }
    std::int64_t integer(const std::string& name, std::int64_t lo, std::int64_t hi) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::integer || s.elements() != 1) fail("attribute " + name + " is not an integer");
        const std::int64_t v = h5::read_int_attribute(file_, name);
        if (v < lo || v > hi) fail(fmt::format("attribute {} = {} is out of range: accepted {} to {}", name, v, lo, hi));
        return v;
    }
    double number(const std::string& name) const
    {
        const h5::Shape s = shape(name);
        if ((s.type != h5::TypeClass::floating && s.type != h5::TypeClass::integer) || s.elements() != 1) {
            fail("attribute " + name + " is not a number");
        }
        const double v = h5::read_double_attribute(file_, name);
        if (!std::isfinite(v)) fail(fmt::format("attribute {} = {} is not finite", name, v));
        return v;
    }
    std::vector<std::string> texts(const std::string& name) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::string || s.scalar) fail("attribute " + name + " is not a list of texts");
        return h5::read_string_vector_attribute(file_, name);
    }
    std::vector<std::uint64_t> integers(const std::string& name) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::integer || s.scalar) fail("attribute " + name + " is not a list of integers");
        return h5::read_u64_vector_attribute(file_, name);
    }

    h5::Id dataset(const std::string& name) const
    {
        if (h5::object_type(file_, name) != h5::ObjectType::dataset) fail(name + " is missing or not a dataset");
        return h5::open_dataset(file_, name);
    }

private:
    h5::Shape shape(const std::string& name) const
    {
        const std::optional<h5::Shape> s = h5::attribute_shape(file_, name);
        if (!s) fail("attribute " + name + " is missing");
        return *s;
    }

    hid_t file_;
    std::string path_;
};

// Opens `path` read-only, saying what it is when it is not HDF5 at all.
h5::Id open_hdf5(const fs::path& path)
{
    const std::string p = path.string();
    std::error_code ec;
    if (!fs::exists(path, ec)) throw FormatError(p + ": no such file");
    if (!fs::is_regular_file(path, ec)) throw FormatError(p + " is " + describe_file(path) + ", not a result file");
    if (!h5::is_hdf5(path)) throw FormatError(p + " is " + describe_file(path) + ", not a superball result");
    try {
        return h5::open_file(path, false);
    } catch (const h5::Error& e) {
        throw FormatError(p + " is an HDF5 file that cannot be opened, damaged or truncated (" + e.what() + ")");
    }
}

}  // namespace

std::uint64_t ResultInfo::points() const
{
    std::uint64_t n = 1;
    for (const std::uint64_t s : shape) n *= s;
    return n;
}

std::string describe_file(const fs::path& path)
{
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) return "nothing (no such file)";
    if (fs::is_directory(st)) return "a directory";
    if (!fs::is_regular_file(st)) return "not a regular file";
    const auto size = fs::file_size(path, ec);
    if (!ec && size == 0) return "an empty file";
    if (h5::is_hdf5(path)) {
        try {
            const h5::Id f = h5::open_file(path, false);
            if (h5::has_attribute(f, layout::kind_attribute) || h5::has_attribute(f, "job_toml")) {
                return "a superball file";
            }
            return "an HDF5 file that is not a superball result";
        } catch (const h5::Error&) {
            return "an HDF5 file that cannot be opened (damaged or truncated)";
        }
    }
    std::ifstream in(path, std::ios::binary);
    std::string head(512, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    const bool text = std::all_of(head.begin(), head.end(), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return u >= 0x20 || c == '\n' || c == '\r' || c == '\t';
    });
    if (!text) return fmt::format("a binary file of {} bytes", size);
    std::string first = head.substr(0, head.find('\n')).substr(0, 40);
    return fmt::format("a text file of {} bytes, beginning \"{}\"", size, first);
}

ResultReader::ResultReader(const fs::path& path) : path_(path), file_(open_hdf5(path))
{
    try {
        validate();
    } catch (const h5::Error& e) {
        // A structure HDF5 itself cannot read (checksums of its metadata, broken links).
        throw FormatError(path.string() + " is damaged: " + e.what());
    }
}

void ResultReader::validate()
{
    const fs::path& path = path_;
    const Checker check(file_, path);
    ResultInfo& in = info_;
    if (!h5::has_attribute(file_, layout::kind_attribute)) {
        if (h5::has_attribute(file_, "job_toml") && h5::has_attribute(file_, "software_version")) {
            std::string version = "?";
            try {
                version = h5::read_string_attribute(file_, "software_version");
            } catch (const h5::Error&) {
            }
            check.fail("written by superball " + version + " in the layout before netCDF conventions, which this version "
                       "does not read; run the job again with this version");
        }
        check.fail("an HDF5 file that is not a superball result (no attribute " + std::string(layout::kind_attribute) + ")");
    }
    const std::string kind = check.text(layout::kind_attribute);
    if (kind != layout::kind_result && kind != layout::kind_partial) {
        check.fail(fmt::format("attribute {} = \"{}\" is neither \"{}\" nor \"{}\"", layout::kind_attribute, kind,
                               layout::kind_result, layout::kind_partial));
    }
    in.kind = kind == layout::kind_result ? FileKind::result : FileKind::partial;
    check.integer("superball_format", layout::format_version, layout::format_version);

    in.coordinate_system = check.text("coordinate_system");
    if (in.coordinate_system != "canonical" && in.coordinate_system != "physical") {
        check.fail("attribute coordinate_system = \"" + in.coordinate_system + "\" is neither canonical nor physical");
    }
    const std::vector<std::string> coordinates = coordinates_of(in.coordinate_system);
    in.axis_names = check.texts("axis_names");
    if (in.axis_names.empty() || in.axis_names.size() > 4) {
        check.fail(fmt::format("attribute axis_names lists {} axes: accepted 1 to 4", in.axis_names.size()));
    }
    std::set<std::string> seen;
    for (const std::string& a : in.axis_names) {
        if (std::find(coordinates.begin(), coordinates.end(), a) == coordinates.end() && !is_coefficient(a)) {
            check.fail(fmt::format("attribute axis_names names \"{}\", which is neither a {} coordinate ({}) nor a model "
                                   "coefficient",
                                   a, in.coordinate_system, fmt::join(coordinates, ", ")));
        }
        if (!seen.insert(a).second) check.fail("attribute axis_names names \"" + a + "\" twice");
    }
    for (const std::string& c : coordinates) {
        if (std::find(in.axis_names.begin(), in.axis_names.end(), c) == in.axis_names.end()) {
            in.fixed.emplace_back(c, check.number("fixed_" + c));
        }
    }
    in.max_bounces = check.integer("max_bounces", 1, max_max_bounces);
    in.software_version = check.text("software_version");
    in.job_toml = check.text("job_toml");
    in.job_fingerprint = check.text("job_fingerprint");
    in.mpi_ranks = check.integer("mpi_ranks", 0, std::int64_t{1} << 40);
    in.wall_seconds = check.number("wall_seconds");
    if (in.wall_seconds < 0) check.fail(fmt::format("attribute wall_seconds = {} is negative", in.wall_seconds));
    in.complete = check.integer("complete", 0, 1) == 1;
    if (in.kind == FileKind::result && !in.complete) {
        check.fail("attribute complete = 0 contradicts superball_file = result (a result is written complete)");
    }
    if (in.kind == FileKind::partial && in.complete) {
        check.fail("attribute complete = 1 contradicts superball_file = partial (a run in progress)");
    }
    // The model: a coefficient is a number in its range, or names the axis that sweeps it.
    for (const char* key : {"e_wall", "alpha_wall", "e_floor", "alpha_floor"}) {
        const std::optional<h5::Shape> s = h5::attribute_shape(file_, key);
        if (s && s->type == h5::TypeClass::string) {
            const std::string v = check.text(key);
            const std::string axis = v.rfind("axis:", 0) == 0 ? v.substr(5) : "";
            if (std::find(in.axis_names.begin(), in.axis_names.end(), axis) == in.axis_names.end() || !is_coefficient(axis)) {
                check.fail(fmt::format("attribute {} = \"{}\" names no coefficient axis of the file", key, v));
            }
            continue;
        }
        const double v = check.number(key);
        const bool normal = key[0] == 'e';
        if (normal ? !(v > 0 && v <= 1) : !(v >= -1 && v <= 1)) {
            check.fail(fmt::format("attribute {} = {} is out of range: accepted {}", key, v,
                                   normal ? "0 < e <= 1" : "-1 <= alpha <= 1"));
        }
    }

    // The data.
    counts_ = check.dataset(layout::wall_bounces);
    outcomes_ = check.dataset(layout::outcome);
    const h5::Shape cs = h5::dataset_shape_of(counts_);
    const h5::Shape os = h5::dataset_shape_of(outcomes_);
    if (cs.type != h5::TypeClass::integer || cs.is_signed || (cs.bytes != 2 && cs.bytes != 4)) {
        check.fail("/wall_bounces is not of unsigned 16- or 32-bit integers");
    }
    if (os.type != h5::TypeClass::integer || os.is_signed || os.bytes != 1) check.fail("/outcome is not of unsigned bytes");
    if (cs.dims.size() != in.axis_names.size()) {
        check.fail(fmt::format("/wall_bounces has {} dimensions {} but axis_names lists {} axes ({})", cs.dims.size(),
                               dims_text(cs.dims), in.axis_names.size(), fmt::join(in.axis_names, ", ")));
    }
    if (os.dims != cs.dims) {
        check.fail("/outcome " + dims_text(os.dims) + " and /wall_bounces " + dims_text(cs.dims) + " differ in shape");
    }
    if (std::find(cs.dims.begin(), cs.dims.end(), hsize_t{0}) != cs.dims.end()) check.fail("/wall_bounces is empty");
    in.shape.assign(cs.dims.begin(), cs.dims.end());
    in.count_bytes = cs.bytes;
    if (in.max_bounces > 65535 && in.count_bytes == 2) {
        check.fail(fmt::format("max_bounces = {} does not fit the 16-bit counts of /wall_bounces", in.max_bounces));
    }
    for (std::size_t k = 0; k < in.axis_names.size(); ++k) axis(k);

    if (in.kind == FileKind::result) return;
    in.tile_shape = check.integers("tile_shape");
    if (in.tile_shape.size() != in.shape.size()) {
        check.fail(fmt::format("attribute tile_shape has {} entries for {} dimensions", in.tile_shape.size(), in.shape.size()));
    }
    for (std::size_t k = 0; k < in.shape.size(); ++k) {
        if (in.tile_shape[k] < 1 || in.tile_shape[k] > in.shape[k]) {
            check.fail(fmt::format("attribute tile_shape = ({}) does not fit the data {}", fmt::join(in.tile_shape, ", "),
                                   dims_text(cs.dims)));
        }
    }
    in.tiles = Tiling(in.shape, in.tile_shape).tiles();
    for (const char* name : {layout::tile_done, layout::tile_checksum}) {
        const h5::Shape s = h5::dataset_shape_of(check.dataset(name));
        const std::size_t bytes = name == layout::tile_done ? 1 : 8;
        if (s.type != h5::TypeClass::integer || s.is_signed || s.bytes != bytes || s.dims != std::vector<hsize_t>{in.tiles}) {
            check.fail(fmt::format("{} is not {} unsigned {}-bit integers, one per tile", name, in.tiles, 8 * bytes));
        }
    }
    done_.resize(in.tiles);
    h5::check(H5Dread(h5::open_dataset(file_, layout::tile_done), H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                      done_.data()),
              "read " + std::string(layout::tile_done));
    for (std::uint64_t t = 0; t < in.tiles; ++t) {
        if (done_[t] > 1) check.fail(fmt::format("{} holds {} for tile {}: accepted 0 or 1", layout::tile_done, done_[t], t));
    }
    in.tiles_done = static_cast<std::uint64_t>(std::count(done_.begin(), done_.end(), std::uint8_t{1}));
}

std::vector<double> ResultReader::axis(std::size_t k) const
{
    const std::string name = "/" + info_.axis_names.at(k);
    const Checker check(file_, path_);
    const h5::Id d = check.dataset(name);
    const h5::Shape s = h5::dataset_shape_of(d);
    if (s.type != h5::TypeClass::floating || s.dims != std::vector<hsize_t>{info_.shape[k]}) {
        check.fail(fmt::format("{} is not {} floating-point samples (dimension {} of the data)", name, info_.shape[k], k));
    }
    std::vector<double> v(info_.shape[k]);
    h5::check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "read " + name);
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!std::isfinite(v[i])) check.fail(fmt::format("{} holds {} at {}: samples must be finite", name, v[i], i));
        if (i > 0 && !(v[i] > v[i - 1])) {
            check.fail(fmt::format("{} is not increasing at {} ({} after {})", name, i, v[i], v[i - 1]));
        }
    }
    return v;
}

std::vector<std::uint8_t> ResultReader::tiles_done() const { return done_; }

std::vector<std::uint64_t> ResultReader::tile_checksums() const
{
    std::vector<std::uint64_t> sums(info_.tiles);
    if (info_.kind == FileKind::partial) {
        h5::check(H5Dread(h5::open_dataset(file_, layout::tile_checksum), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                          sums.data()),
                  "read " + std::string(layout::tile_checksum));
    }
    return sums;
}

std::vector<std::uint64_t> ResultReader::damaged_tiles() const
{
    std::vector<std::uint64_t> bad;
    if (info_.kind != FileKind::partial) return bad;
    const std::vector<std::uint64_t> sums = tile_checksums();
    const Tiling tiling(info_.shape, info_.tile_shape);
    std::vector<std::byte> counts, outcomes;
    for (std::uint64_t t = 0; t < info_.tiles; ++t) {
        if (done_[t] == 0) continue;
        // The chunks as stored, the bytes the checksum was taken of.
        const std::vector<hsize_t> origin = to_hsize(tiling.box(t).start);
        for (auto [d, buf] : {std::pair{counts_.get(), &counts}, std::pair{outcomes_.get(), &outcomes}}) {
            hsize_t bytes = 0;
            h5::check(H5Dget_chunk_storage_size(d, origin.data(), &bytes), "H5Dget_chunk_storage_size");
            buf->resize(bytes);
            std::uint32_t filters = 0;
            h5::check(H5Dread_chunk(d, H5P_DEFAULT, origin.data(), &filters, buf->data()), "read a chunk");
        }
        if (tile_checksum(t, counts, outcomes) != sums[t]) bad.push_back(t);
    }
    return bad;
}

std::uint64_t ResultReader::read(const Box& box, std::span<std::uint32_t> counts, std::span<std::uint8_t> outcomes) const
{
    try {
        return read_checked(box, counts, outcomes);
    } catch (const h5::Error& e) {
        throw FormatError(path_.string() + " cannot be read: " + e.what());
    }
}

std::uint64_t ResultReader::read_checked(const Box& box, std::span<std::uint32_t> counts,
                                         std::span<std::uint8_t> outcomes) const
{
    const std::vector<hsize_t> start = to_hsize(box.start), count = to_hsize(box.count);
    const h5::Id memory = h5::simple_space(count);
    for (const hid_t d : {counts_.get(), outcomes_.get()}) {
        const h5::Id space = h5::space_id(H5Dget_space(d), "H5Dget_space");
        h5::select_box(space, start, count);
        if (d == counts_.get()) {
            h5::check(H5Dread(d, H5T_NATIVE_UINT32, memory, space, H5P_DEFAULT, counts.data()), "read /wall_bounces");
        } else {
            h5::check(H5Dread(d, H5T_NATIVE_UINT8, memory, space, H5P_DEFAULT, outcomes.data()), "read /outcome");
        }
    }
    // Points of tiles not done hold whatever the disk held: mask them, a run of a row at a
    // time (a row of the box crosses a tile every tile_shape.back() points).
    std::vector<std::uint8_t> computed;
    std::uint64_t missing = 0;
    if (info_.kind == FileKind::partial && info_.tiles_done < info_.tiles) {
        const std::size_t d = box.count.size();
        computed.assign(box.points(), 1);
        Extent per_axis(d);
        for (std::size_t k = 0; k < d; ++k) per_axis[k] = (info_.shape[k] + info_.tile_shape[k] - 1) / info_.tile_shape[k];
        const std::uint64_t row = box.count[d - 1], width = info_.tile_shape[d - 1];
        Extent index(d, 0);
        for (std::uint64_t p = 0; p < box.points(); p += row) {
            std::uint64_t prefix = 0;  // the tile's index without its last coordinate
            for (std::size_t k = 0; k + 1 < d; ++k) prefix = prefix * per_axis[k] + (box.start[k] + index[k]) / info_.tile_shape[k];
            for (std::uint64_t j = 0; j < row;) {
                const std::uint64_t column = box.start[d - 1] + j;
                const std::uint64_t end = std::min(row, j + width - column % width);
                if (done_[prefix * per_axis[d - 1] + column / width] == 0) {
                    std::fill(computed.begin() + static_cast<std::ptrdiff_t>(p + j), computed.begin() + static_cast<std::ptrdiff_t>(p + end), 0);
                    std::fill(counts.begin() + static_cast<std::ptrdiff_t>(p + j), counts.begin() + static_cast<std::ptrdiff_t>(p + end), 0u);
                    std::fill(outcomes.begin() + static_cast<std::ptrdiff_t>(p + j), outcomes.begin() + static_cast<std::ptrdiff_t>(p + end), 0);
                    missing += end - j;
                }
                j = end;
            }
            for (std::size_t k = d - 1; k-- > 0;) {
                if (++index[k] < box.count[k]) break;
                index[k] = 0;
            }
        }
    }
    validate_values(box, counts, outcomes, computed);
    return missing;
}

void ResultReader::validate_values(const Box& box, std::span<const std::uint32_t> counts,
                                   std::span<const std::uint8_t> outcomes, std::span<const std::uint8_t> computed) const
{
    const auto max = static_cast<std::uint64_t>(info_.max_bounces);
    for (std::size_t p = 0; p < outcomes.size(); ++p) {
        if (!computed.empty() && computed[p] == 0) continue;
        const std::uint8_t o = outcomes[p];
        const std::uint32_t n = counts[p];
        const bool bad_outcome = o > 3;
        const bool bad_count = o == 0 ? n != 0 : o == 3 ? n != max : n > max;
        if (!bad_outcome && !bad_count) continue;
        // The point's index, for the message.
        Extent at(box.count.size());
        std::uint64_t rest = p;
        for (std::size_t k = box.count.size(); k-- > 0;) {
            at[k] = box.start[k] + rest % box.count[k];
            rest /= box.count[k];
        }
        const std::string where = fmt::format("at ({})", fmt::join(at, ", "));
        if (bad_outcome) {
            throw FormatError(fmt::format("{}: /outcome holds {} {}: outcome codes are 0 to 3 ({}); the file is damaged",
                                          path_.string(), o, where, layout::outcome_meanings));
        }
        throw FormatError(fmt::format("{}: /wall_bounces holds {} {} with outcome {}, which allows {}; the file is damaged",
                                      path_.string(), n, where, o,
                                      o == 0 ? std::string("0") : o == 3 ? fmt::format("exactly max_bounces = {}", max)
                                                                         : fmt::format("at most max_bounces = {}", max)));
    }
}

OutcomeCounts ResultReader::outcome_counts() const
{
    OutcomeCounts out;
    std::vector<std::uint32_t> counts;
    std::vector<std::uint8_t> outcomes;
    const auto add = [&](const Box& box) {
        counts.resize(box.points());
        outcomes.resize(box.points());
        read(box, counts, outcomes);
        for (const std::uint8_t o : outcomes) ++out.by_outcome[o];
    };
    if (info_.kind == FileKind::partial) {
        // Only the tiles done: an interrupted run of 10^10 points may have done few.
        const Tiling tiling(info_.shape, info_.tile_shape);
        std::uint64_t computed = 0;
        for (std::uint64_t t = 0; t < info_.tiles; ++t) {
            if (done_[t] == 0) continue;
            const Box box = tiling.box(t);
            add(box);
            computed += box.points();
        }
        out.not_computed = info_.points() - computed;
        return out;
    }
    // A result: about 16 Mi points at a time, whole rows along the first axis (at least one).
    const std::size_t d = info_.shape.size();
    std::uint64_t row = 1;
    for (std::size_t k = 1; k < d; ++k) row *= info_.shape[k];
    const std::uint64_t rows = std::max<std::uint64_t>(1, (std::uint64_t{1} << 24) / row);
    for (std::uint64_t first = 0; first < info_.shape[0]; first += rows) {
        Box box{Extent(d, 0), info_.shape};
        box.start[0] = first;
        box.count[0] = std::min(rows, info_.shape[0] - first);
        add(box);
    }
    return out;
}

}  // namespace superball
