// XDMF sidecar: lets ParaView and VisIt open a 2-D or 3-D result directly.
#pragma once

#include <filesystem>

#include "result_file.hpp"

namespace superball {

// Writes `<result>.xmf` next to `result` (a rectilinear grid whose nodes are the
// cell-centred samples) and returns its path; 1-D results get none (XDMF has no 1-D
// rectilinear mesh) and an empty path is returned.
std::filesystem::path write_xdmf(const std::filesystem::path& result, const ResultInfo& info);

}  // namespace superball
