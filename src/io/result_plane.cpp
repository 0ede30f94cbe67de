#include "result_plane.hpp"

#include <algorithm>
#include <limits>
#include <memory>

#include "core/input.hpp"
#include "hdf5.hpp"
#include "job/job.hpp"
#include "result_file.hpp"

namespace superball {

namespace {

// The open datasets and the geometry a reader needs; shared by the copies of the reader.
struct PlaneReader {
    h5::Id file;
    h5::Id wall_bounces;
    h5::Id outcome;
    std::vector<hsize_t> shape;          // of the datasets
    std::size_t row_dim = 0, col_dim = 1;
    std::optional<std::size_t> slice_dim;
    hsize_t slice_index = 0;
    // Tiles not done, for masking: empty when every tile is done.
    std::vector<std::uint8_t> tile_done;
    std::vector<std::uint64_t> tile_shape, tiles_per_axis;

    void read(std::size_t first, std::size_t count, std::span<std::uint32_t> wb, std::span<std::uint8_t> out) const
    {
        std::vector<hsize_t> start(shape.size(), 0), extent(shape.size(), 1);
        start[row_dim] = first;
        extent[row_dim] = count;
        extent[col_dim] = shape[col_dim];
        if (slice_dim) start[*slice_dim] = slice_index;
        // The memory space has the shape of the selection, not a flat one: HDF5 then copies
        // chunk by chunk instead of mapping every element to its chunk (5x less CPU).
        const h5::Id mem =
            h5::space_id(H5Screate_simple(static_cast<int>(extent.size()), extent.data(), nullptr), "H5Screate_simple");
        for (const hid_t d : {wall_bounces.get(), outcome.get()}) {
            const h5::Id space = h5::space_id(H5Dget_space(d), "H5Dget_space");
            h5::check(H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, extent.data(), nullptr),
                      "H5Sselect_hyperslab");
            if (d == wall_bounces.get()) {
                h5::check(H5Dread(d, H5T_NATIVE_UINT32, mem, space, H5P_DEFAULT, wb.data()), "read /wall_bounces");
            } else {
                h5::check(H5Dread(d, H5T_NATIVE_UINT8, mem, space, H5P_DEFAULT, out.data()), "read /outcome");
            }
        }
        if (!tile_done.empty()) mask_missing_tiles(start, count, out);
    }

    // Chunks of tiles never written hold whatever the disk held: read them as invalid.
    void mask_missing_tiles(std::vector<hsize_t> at, std::size_t count, std::span<std::uint8_t> out) const
    {
        const std::size_t cols = shape[col_dim];
        const std::size_t first = at[row_dim];
        for (std::size_t k = 0; k < count; ++k) {
            at[row_dim] = first + k;
            for (std::size_t j0 = 0; j0 < cols; j0 += tile_shape[col_dim]) {
                at[col_dim] = j0;
                std::uint64_t t = 0;
                for (std::size_t a = 0; a < shape.size(); ++a) t = t * tiles_per_axis[a] + at[a] / tile_shape[a];
                if (tile_done[t]) continue;
                const std::size_t j1 = std::min<std::size_t>(cols, j0 + tile_shape[col_dim]);
                std::fill(out.begin() + static_cast<std::ptrdiff_t>(k * cols + j0),
                          out.begin() + static_cast<std::ptrdiff_t>(k * cols + j1), std::uint8_t{0});
            }
        }
    }
};

// Spacing of the samples along `axis`: from the samples, or for a single sample from the
// job's range (max - min) / n; NaN if neither says.
double cell_size(hid_t file, const std::string& axis, const ResultInfo& info)
{
    const h5::Id d = h5::dataset_id(H5Dopen2(file, ("/axes/" + axis).c_str(), H5P_DEFAULT), "open /axes/" + axis);
    const auto shape = h5::dataset_shape(d);
    if (shape.size() == 1 && shape[0] >= 2) {
        std::vector<double> s(shape[0]);
        h5::check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data()), "read /axes/" + axis);
        return (s.back() - s.front()) / static_cast<double>(s.size() - 1);
    }
    try {
        const Job job = parse_job(info.job_toml, "job_toml");
        for (const Coordinate& c : job.grid) {
            if (c.name == axis && c.range) return (c.range->max - c.range->min) / static_cast<double>(c.range->n);
        }
    } catch (const InputError&) {
    }
    return std::numeric_limits<double>::quiet_NaN();
}

std::string shape_text(const ResultInfo& info)
{
    std::string s;
    for (std::size_t k = 0; k < info.shape.size(); ++k) {
        s += (k ? " x " : "") + std::to_string(info.shape[k]) + " " + info.axis_names[k];
    }
    return s;
}

}  // namespace

ResultPlane open_result_plane(const std::filesystem::path& path, std::optional<Slice> slice, ClassRule rule)
{
    const std::string p = path.string();
    if (!std::filesystem::exists(path)) throw InputError(p + ": no such file");
    ResultInfo info;
    try {
        info = read_result_info(path);
    } catch (const h5::Error& e) {
        throw InputError(p + " is not a superball result (" + e.what() + ")");
    }
    const std::size_t rank = info.shape.size();
    if (info.axis_names.size() != rank) throw InputError(p + ": axis_names does not match the shape of /wall_bounces");
    if (rank < 2) {
        throw InputError(p + " is a 1-D result (" + shape_text(info) +
                         "): analyse needs a 2-D result or a 2-D slice of a 3-D one");
    }
    if (rank == 2 && slice) throw InputError("--slice applies to 3-D results only; " + p + " is 2-D (" + shape_text(info) + ")");
    if (rank == 3 && !slice) {
        throw InputError(p + " is a 3-D result (" + shape_text(info) + "): choose a plane with --slice AXIS=INDEX, e.g. --slice " +
                         info.axis_names[1] + "=" + std::to_string(info.shape[1] / 2));
    }
    if (rank > 3) throw InputError(p + ": results have at most 3 axes, this one has " + std::to_string(rank));
    std::optional<std::size_t> sliced;
    if (slice) {
        for (std::size_t a = 0; a < rank; ++a) {
            if (slice->axis == info.axis_names[a] || slice->axis == std::to_string(a)) sliced = a;
        }
        if (!sliced) {
            throw InputError("--slice: axis '" + slice->axis + "' is not one of " + info.axis_names[0] + ", " +
                             info.axis_names[1] + ", " + info.axis_names[2] + " (or 0, 1, 2)");
        }
        if (slice->index >= info.shape[*sliced]) {
            throw InputError("--slice: index " + std::to_string(slice->index) + " is outside axis " +
                             info.axis_names[*sliced] + " (0 to " + std::to_string(info.shape[*sliced] - 1) + ")");
        }
    }
    const std::int64_t label_limit = rule == ClassRule::count ? std::int64_t{0xfffffffe} : (std::int64_t{1} << 30) - 2;
    if (info.max_bounces > label_limit) {
        throw InputError(p + ": max_bounces = " + std::to_string(info.max_bounces) + " is too large for " +
                         (rule == ClassRule::count ? "analyse" : "--with-outcome") + " (at most " +
                         std::to_string(label_limit) + ")");
    }

    auto reader = std::make_shared<PlaneReader>();
    reader->file = h5::file_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open " + p);
    reader->wall_bounces = h5::dataset_id(H5Dopen2(reader->file, "/wall_bounces", H5P_DEFAULT), "open /wall_bounces");
    reader->outcome = h5::dataset_id(H5Dopen2(reader->file, "/outcome", H5P_DEFAULT), "open /outcome");
    reader->shape = h5::dataset_shape(reader->wall_bounces);
    if (h5::dataset_shape(reader->outcome) != reader->shape) throw InputError(p + ": /outcome and /wall_bounces differ in shape");
    std::vector<std::size_t> plane_dims;
    for (std::size_t a = 0; a < rank; ++a) {
        if (a != sliced) plane_dims.push_back(a);
    }
    reader->row_dim = plane_dims[0];
    reader->col_dim = plane_dims[1];
    reader->slice_dim = sliced;
    reader->slice_index = slice ? slice->index : 0;
    ResultPlane plane;
    plane.tiles_missing = info.tiles - info.tiles_done;
    if (plane.tiles_missing > 0) {
        const h5::Id d =
            h5::dataset_id(H5Dopen2(reader->file, "/progress/tile_done", H5P_DEFAULT), "open /progress/tile_done");
        reader->tile_done.resize(info.tiles);
        h5::check(H5Dread(d, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, reader->tile_done.data()), "read tile_done");
        reader->tile_shape = info.tile_shape;
        for (std::size_t a = 0; a < rank; ++a) {
            reader->tiles_per_axis.push_back((info.shape[a] + info.tile_shape[a] - 1) / info.tile_shape[a]);
        }
    }

    plane.row_axis = info.axis_names[reader->row_dim];
    plane.col_axis = info.axis_names[reader->col_dim];
    if (sliced) plane.sliced_axis = info.axis_names[*sliced];
    plane.cell = {cell_size(reader->file, plane.row_axis, info), cell_size(reader->file, plane.col_axis, info)};
    plane.max_bounces = info.max_bounces;
    plane.source.rows = info.shape[reader->row_dim];
    plane.source.cols = info.shape[reader->col_dim];
    // A band one tile high reads each chunk once; capped so that a block stays near 4 Mi points.
    const std::size_t cap = std::max<std::size_t>(1, (std::size_t{1} << 22) / std::max<std::size_t>(1, plane.source.cols));
    plane.source.block_rows = std::clamp<std::size_t>(info.tile_shape[reader->row_dim], 1, cap);
    plane.source.read = [reader](std::size_t first, std::size_t count, std::span<std::uint32_t> wb,
                                 std::span<std::uint8_t> out) { reader->read(first, count, wb, out); };
    return plane;
}

}  // namespace superball
