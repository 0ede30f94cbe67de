#include "layers.hpp"

#include <cmath>
#include <optional>

#include "core/input.hpp"
#include "io/layout.hpp"
#include "job/result_json.hpp"

namespace superball::serve {

namespace {

int coordinate_index(const std::string& name)
{
    for (int k = 0; k < 3; ++k) {
        if (axis_names[static_cast<std::size_t>(k)] == name) return k;
    }
    return -1;
}

// The cell of `r` that holds x (samples are cell centres), or nothing outside the range.
std::optional<std::uint64_t> cell_of(const Range& r, double x)
{
    const double at = (x - r.min) / (r.max - r.min) * static_cast<double>(r.n);
    if (!(at >= 0.0 && at < static_cast<double>(r.n))) return std::nullopt;
    return static_cast<std::uint64_t>(at);
}

nlohmann::ordered_json range_json(const Range& r) { return {{"min", r.min}, {"max", r.max}, {"n", r.n}}; }

}  // namespace

Layer::Layer(const std::filesystem::path& path) : reader_(path)
{
    const ResultInfo& info = reader_.info();
    const std::string name = path.string();
    if (info.coordinate_system != "canonical") {
        throw InputError(name + " is a " + info.coordinate_system +
                         " result: accepted canonical results (axes among xi, U, W) as layers");
    }
    job_ = parse_job(info.job_toml, name + " (its " + layout::attr::job_toml.name + " attribute)");
    if (!job_.parameters.empty()) {
        throw InputError(name + " sweeps a model coefficient: accepted results of one model as layers");
    }
    for (const std::string& axis : info.axis_names) dims_.push_back(coordinate_index(axis));
    if (dims_.size() < 2) throw InputError(name + " has 1 axis: accepted results of 2 or 3 axes among xi, U, W as layers");
    if (info.kind == FileKind::partial) tiles_done_ = reader_.tiles_done();
}

nlohmann::ordered_json Layer::json(std::size_t index) const
{
    const ResultInfo& info = reader_.info();
    nlohmann::ordered_json out = {{"index", index},
                                  {"path", reader_.path().string()},
                                  {"kind", info.kind == FileKind::result ? "result" : "partial"},
                                  {"tiles", info.tiles},
                                  {"tiles_done", info.tiles_done}};
    nlohmann::ordered_json& grid = out["grid"] = nlohmann::ordered_json::object();
    for (const Coordinate& c : job_.grid) grid[c.name] = c.is_range() ? range_json(*c.range) : nlohmann::ordered_json(*c.fixed);
    out["model"] = model_json(job_.model);
    out["max_bounces"] = job_.max_bounces;
    // The first axis across and the last up (for a volume: xi and W, the slices of the
    // quickstart job), the third coordinate fixed (a volume's middle axis at its middle sample).
    const auto axis = [&](std::size_t d) { return std::string(axis_names[static_cast<std::size_t>(dims_[d])]); };
    const int fixed = 3 - dims_.front() - dims_.back();
    const Coordinate& f = job_.grid[static_cast<std::size_t>(fixed)];
    const double value = f.is_range() ? f.range->sample(f.range->n / 2) : *f.fixed;
    out["view"] = {{"x", axis(0)}, {"y", axis(dims_.size() - 1)}, {"fixed", axis_names[static_cast<std::size_t>(fixed)]},
                   {"value", value}};
    return out;
}

bool Layer::holds(const View& v, std::optional<std::uint64_t>& slice) const
{
    const Model& m = job_.model;
    if (!(m.wall.e == v.model.wall.e && m.wall.alpha == v.model.wall.alpha && m.floor.e == v.model.floor.e &&
          m.floor.alpha == v.model.floor.alpha && job_.max_bounces == v.max_bounces)) {
        return false;
    }
    const Coordinate& gx = job_.grid[static_cast<std::size_t>(v.plane.x)];
    const Coordinate& gy = job_.grid[static_cast<std::size_t>(v.plane.y)];
    const Coordinate& gf = job_.grid[static_cast<std::size_t>(v.plane.fixed)];
    if (!gx.is_range() || !gy.is_range()) return false;
    // The plane: the file's fixed value, or the slice of its third axis that holds v.fixed.
    slice.reset();
    if (gf.is_range()) {
        slice = cell_of(*gf.range, v.fixed);
        if (!slice) return false;
    } else if (*gf.fixed != v.fixed) {
        return false;
    }
    // Zoomed in beyond the file's samples: computed.
    const auto spacing = [](const Range& r) { return (r.max - r.min) / static_cast<double>(r.n); };
    return !(spacing(v.x) < spacing(*gx.range) || spacing(v.y) < spacing(*gy.range));
}

bool Layer::fill(const View& v, RegionCounts& out, std::vector<std::uint8_t>& from_file,
                 std::vector<std::uint8_t>& not_computed) const
{
    std::optional<std::uint64_t> slice;
    if (!holds(v, slice)) return false;
    const Coordinate& gx = job_.grid[static_cast<std::size_t>(v.plane.x)];
    const Coordinate& gy = job_.grid[static_cast<std::size_t>(v.plane.y)];
    std::vector<std::optional<std::uint64_t>> ix(v.x.n), iy(v.y.n);
    std::uint64_t lo[2] = {UINT64_MAX, UINT64_MAX}, hi[2] = {0, 0};
    const auto cells = [&](const Range& view, const Range& file, std::vector<std::optional<std::uint64_t>>& idx, int a) {
        for (std::uint64_t i = 0; i < view.n; ++i) {
            idx[i] = cell_of(file, view.sample(i));
            if (idx[i]) {
                lo[a] = std::min(lo[a], *idx[i]);
                hi[a] = std::max(hi[a], *idx[i]);
            }
        }
    };
    cells(v.x, *gx.range, ix, 0);
    cells(v.y, *gy.range, iy, 1);
    if (lo[0] > hi[0] || lo[1] > hi[1]) return false;
    Box box;
    for (const int d : dims_) {
        if (d == v.plane.x) {
            box.start.push_back(lo[0]);
            box.count.push_back(hi[0] - lo[0] + 1);
        } else if (d == v.plane.y) {
            box.start.push_back(lo[1]);
            box.count.push_back(hi[1] - lo[1] + 1);
        } else {
            box.start.push_back(*slice);
            box.count.push_back(1);
        }
    }
    if (box.points() > max_layer_read) return false;
    std::vector<std::uint32_t> counts(box.points());
    std::vector<std::uint8_t> outcomes(box.points());
    reader_.read(box, counts, outcomes);

    // Offsets in the box (row-major) of one step along x and along y.
    std::uint64_t stride[2] = {0, 0}, step = 1;
    for (std::size_t d = dims_.size(); d-- > 0;) {
        if (dims_[d] == v.plane.x) stride[0] = step;
        if (dims_[d] == v.plane.y) stride[1] = step;
        step *= box.count[d];
    }
    const Extent& tile = reader_.info().tile_shape;
    for (std::uint64_t j = 0; j < v.y.n; ++j) {
        if (!iy[j]) continue;
        for (std::uint64_t i = 0; i < v.x.n; ++i) {
            if (!ix[i]) continue;
            const std::uint64_t at = (*ix[i] - lo[0]) * stride[0] + (*iy[j] - lo[1]) * stride[1];
            const std::uint64_t k = j * v.x.n + i;
            out.wall_bounces[k] = counts[at];
            out.outcomes[k] = outcomes[at];
            from_file[k] = 1;
            if (!tiles_done_.empty()) {
                // The point's tile, row-major over the tiles of the file.
                std::uint64_t t = 0;
                for (std::size_t d = 0; d < dims_.size(); ++d) {
                    const std::uint64_t index = dims_[d] == v.plane.x ? *ix[i] : dims_[d] == v.plane.y ? *iy[j] : *slice;
                    const std::uint64_t tiles_along = (reader_.info().shape[d] + tile[d] - 1) / tile[d];
                    t = t * tiles_along + index / tile[d];
                }
                not_computed[k] = tiles_done_[t] ? 0 : 1;
            }
        }
    }
    return true;
}

Layers::Layers(const std::vector<std::filesystem::path>& paths)
{
    for (const auto& p : paths) layers_.push_back(std::make_unique<Layer>(p));
}

nlohmann::ordered_json Layers::json() const
{
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (std::size_t k = 0; k < layers_.size(); ++k) out.push_back(layers_[k]->json(k));
    return out;
}

bool Layers::fill(std::size_t index, const View& v, RegionCounts& out, std::vector<std::uint8_t>& from_file,
                  std::vector<std::uint8_t>& not_computed) const
{
    const std::lock_guard lock(hdf5_);
    return layers_.at(index)->fill(v, out, from_file, not_computed);
}

}  // namespace superball::serve
