// XDMF sidecar: lets ParaView and VisIt open a result directly (ParaView's legacy XDMF
// reader and its Xdmf3 readers, checked by tests/paraview).
//
// The mesh is always 3-D rectilinear, one node per sample: a 2-D (or 1-D) result gets
// its missing dimensions from the job's fixed coordinates, one sample thick at their value,
// in the order of the coordinates (a (xi, W) slice at U = -1 sits at U = -1 inside the
// (xi, U, W) volume, with the same axes); the legacy reader draws 2-D meshes as a line.
// XDMF's X varies fastest: X is the last axis of the mesh, Z the first (canonical: X = W,
// Y = U, Z = xi). Counts are declared signed (HDF5 converts on read) so that VTK's
// interpolation between samples cannot wrap around zero as it does on unsigned 16-bit
// values.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "result_reader.hpp"

namespace superball {

// Writes the sidecar of the complete result at `result` (layout::sidecar_path), of which
// `info` describes the grid (the writer knows it: the file is not read again, which on a
// cluster's result would be gigabytes), naming the result by its file name, so the pair
// keeps working when moved together and from any working directory. Returns its path;
// empty, writing nothing, for a 4-D result (XDMF has no 4-D mesh) and a result whose file
// name has a colon (XDMF cannot name it) or the extension .xmf.
std::filesystem::path write_xdmf(const std::filesystem::path& result, const ResultInfo& info);

// Why `result` gets no sidecar ("" if it gets one).
std::string xdmf_unsupported(const std::filesystem::path& result, const ResultInfo& info);

// `text` with the five XML special characters escaped.
std::string xml_escape(std::string_view text);

}  // namespace superball
