// superball analyse as a library function: the structure of the regions of one plane of a
// result file (measures/structure.hpp), with the settings a user asks for checked against
// the plane.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>

#include "io/result_plane.hpp"
#include "measures/structure.hpp"

namespace superball {

struct AnalyseRequest {
    std::filesystem::path file;
    std::optional<Slice> slice;             // required for 3-D results
    ClassRule rule = ClassRule::count;
    std::size_t box = 5;                    // side of the basin-entropy boxes
    std::optional<std::size_t> eps_max;     // default: default_settings()
    std::optional<std::size_t> box_max;     // default: default_settings()
    std::size_t top = 5;                    // pairs of classes listed by boundary length
};

struct Analysis {
    ResultPlane plane;
    Structure structure;
};

// InputError when a setting does not fit the plane (naming it); FormatError and h5::Error
// from reading the file.
Analysis analyse_result(const AnalyseRequest& request);

}  // namespace superball
