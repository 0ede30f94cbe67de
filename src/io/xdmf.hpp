// XDMF sidecar: lets ParaView and VisIt open a result directly (legacy and Xdmf3 readers).
//
// The mesh is always 3-D rectilinear, one node per sample: a 2-D (or 1-D) result gets
// its missing dimensions from the job's fixed coordinates, one sample thick at their value,
// in the order of the coordinates (a (xi, W) slice at U = -1 sits at U = -1 inside the
// (xi, U, W) volume); the legacy reader draws 2-D meshes transposed, as a line. XDMF's X
// varies fastest: X is the last axis of the data, Z the first. Counts are declared signed
// 32-bit (HDF5 converts on read) so that VTK's interpolation between samples cannot wrap
// around zero as it does on unsigned 16-bit values.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace superball {

// Writes the sidecar of the complete result at `result` (layout::sidecar_path), naming the
// result by its file name, so the pair keeps working when moved together and from any
// working directory. Returns its path; empty for a 4-D result (XDMF has no 4-D mesh).
std::filesystem::path write_xdmf(const std::filesystem::path& result);

// `text` with the five XML special characters escaped.
std::string xml_escape(std::string_view text);

}  // namespace superball
