#include "analyse.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "core/input.hpp"

namespace superball {

Analysis analyse_result(const AnalyseRequest& r)
{
    ResultPlane plane = open_result_plane(r.file, r.slice, r.rule);
    const std::size_t rows = plane.source.rows, cols = plane.source.cols;
    StructureSettings settings = default_settings(rows, cols);
    settings.rule = r.rule;
    settings.cell = plane.cell;
    settings.entropy_box = r.box;
    settings.top_pairs = r.top;
    if (r.eps_max) settings.eps_max = *r.eps_max;
    if (r.box_max) settings.box_max = *r.box_max;
    // The window holds 2 eps_max + 1 rows: beyond the grid it would only cost memory.
    if (settings.eps_max >= std::max(rows, cols)) {
        throw InputError(fmt::format("--eps-max {} is not smaller than the grid ({} x {})", settings.eps_max, rows, cols));
    }
    if (settings.box_max > std::max(rows, cols)) {
        throw InputError(fmt::format("--box-max {} is larger than the grid ({} x {})", settings.box_max, rows, cols));
    }
    if (settings.entropy_box > std::min(rows, cols)) {
        throw InputError(
            fmt::format("--box {} is larger than the grid ({} x {}): no box fits", settings.entropy_box, rows, cols));
    }
    Structure structure = analyse_structure(plane.source, settings);
    return {std::move(plane), std::move(structure)};
}

}  // namespace superball
