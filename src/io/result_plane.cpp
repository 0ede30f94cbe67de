#include "result_plane.hpp"

#include <algorithm>
#include <limits>
#include <memory>

#include "core/input.hpp"
#include "job/job.hpp"
#include "layout.hpp"
#include "result_reader.hpp"

namespace superball {

namespace {

// Spacing of the samples along axis k: from the samples, or for a single sample from the
// job's range (max - min) / n; NaN if neither says.
double cell_size(const ResultReader& reader, std::size_t k)
{
    const std::vector<double> s = reader.axis(k);
    if (s.size() >= 2) return (s.back() - s.front()) / static_cast<double>(s.size() - 1);
    try {
        const Job job = parse_job(reader.info().job_toml, layout::attr::job_toml.name);
        for (const Coordinate* c : job.range_axes()) {
            if (c->name == reader.info().axis_names[k]) return (c->range->max - c->range->min) / static_cast<double>(c->range->n);
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
    auto reader = std::make_shared<const ResultReader>(path);
    const ResultInfo& info = reader->info();
    const std::size_t rank = info.shape.size();
    if (rank < 2) {
        throw InputError(p + " is a 1-D result (" + shape_text(info) +
                         "): analyse needs a 2-D result or a 2-D slice of a 3-D one");
    }
    if (rank == 2 && slice) throw InputError("--slice applies to 3-D results only; " + p + " is 2-D (" + shape_text(info) + ")");
    if (rank == 3 && !slice) {
        throw InputError(p + " is a 3-D result (" + shape_text(info) + "): choose a plane with --slice AXIS=INDEX, e.g. --slice " +
                         info.axis_names[1] + "=" + std::to_string(info.shape[1] / 2));
    }
    if (rank > 3) throw InputError(p + ": analyse reads results of at most 3 axes, this one has " + std::to_string(rank));
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
    std::vector<std::size_t> plane_dims;
    for (std::size_t a = 0; a < rank; ++a) {
        if (a != sliced) plane_dims.push_back(a);
    }
    const std::size_t row_dim = plane_dims[0], col_dim = plane_dims[1];

    ResultPlane plane;
    plane.tiles_missing = info.tiles - info.tiles_done;
    plane.row_axis = info.axis_names[row_dim];
    plane.col_axis = info.axis_names[col_dim];
    if (sliced) plane.sliced_axis = info.axis_names[*sliced];
    plane.cell = {cell_size(*reader, row_dim), cell_size(*reader, col_dim)};
    plane.max_bounces = info.max_bounces;
    plane.source.rows = info.shape[row_dim];
    plane.source.cols = info.shape[col_dim];
    // Blocks of a few Mi points; whatever the chunking, each row is read once.
    const std::size_t cap = std::max<std::size_t>(1, (std::size_t{1} << 22) / std::max<std::size_t>(1, plane.source.cols));
    plane.source.block_rows = std::clamp<std::size_t>(512, 1, cap);
    const std::uint64_t slice_index = slice ? slice->index : 0;
    // Box of rows [first, first + count) of the plane: its points come row-major, a row of
    // the plane after the other (the sliced dimension has one sample).
    plane.source.read = [reader, rank, row_dim, col_dim, sliced, slice_index](
                            std::size_t first, std::size_t count, std::span<std::uint32_t> wb, std::span<std::uint8_t> out) {
        Box box{Extent(rank, 0), Extent(rank, 1)};
        box.start[row_dim] = first;
        box.count[row_dim] = count;
        box.count[col_dim] = reader->info().shape[col_dim];
        if (sliced) box.start[*sliced] = slice_index;
        reader->read(box, wb, out);
    };
    return plane;
}

}  // namespace superball
