// Result files shown as map layers: where a tile's view is the plane, model and
// max_bounces of a file and no finer than its samples, the tile shows the file's values
// (each pixel the sample whose cell holds it); anywhere else it is computed on demand.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/result_reader.hpp"
#include "job/job.hpp"
#include "region.hpp"
#include "view.hpp"

namespace superball::serve {

// Most points a tile reads from a file (12 MB of counts and outcomes read and discarded
// down to one tile): zoomed further out, the tile is computed.
inline constexpr std::uint64_t max_layer_read = std::uint64_t{1} << 22;

class Layer {
public:
    // Opens and validates the file (ResultReader). Throws InputError naming the file when it
    // is not a canonical result of 2 or 3 coordinate axes with no swept coefficient.
    explicit Layer(const std::filesystem::path& path);

    // The file, its grid, model and progress, and the view that shows it, as JSON.
    nlohmann::ordered_json json(std::size_t index) const;

    // Sets the points of `out` (a view's counts) that the file holds at the view's
    // resolution, with from_file[k] = 1; not_computed[k] = 1 for the points of a partial
    // file's tiles not done. Returns false, touching nothing, when the file has nothing for
    // this view. Not thread-safe (HDF5 is not): Layers serialises it.
    bool fill(const View& v, RegionCounts& out, std::vector<std::uint8_t>& from_file,
              std::vector<std::uint8_t>& not_computed) const;

private:
    // The file has data for this view: the same model, the view's plane among its axes at
    // no finer a spacing than its samples; `slice`, the sample of its third axis that holds
    // the plane (none when that coordinate is fixed).
    bool holds(const View& v, std::optional<std::uint64_t>& slice) const;

    ResultReader reader_;
    Job job_;
    std::vector<int> dims_;  // the coordinate (0 xi, 1 U, 2 W) of each dimension of the data
    std::vector<std::uint8_t> tiles_done_;  // partial files
};

class Layers {
public:
    explicit Layers(const std::vector<std::filesystem::path>& paths);

    std::size_t size() const { return layers_.size(); }
    nlohmann::ordered_json json() const;  // [layer, ...]
    // Layer::fill of layer `index`, one at a time.
    bool fill(std::size_t index, const View& v, RegionCounts& out, std::vector<std::uint8_t>& from_file,
              std::vector<std::uint8_t>& not_computed) const;

private:
    std::vector<std::unique_ptr<Layer>> layers_;
    mutable std::mutex hdf5_;
};

}  // namespace superball::serve
