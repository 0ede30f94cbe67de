#include "xdmf.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

#include "layout.hpp"
#include "result_reader.hpp"

namespace superball {

std::string xml_escape(std::string_view text)
{
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&apos;"; break;
            default: out += c;
        }
    }
    return out;
}

namespace {

// One axis of the mesh: a range axis of the data (index >= 0) or a fixed coordinate.
struct MeshAxis {
    std::string name;
    int data_axis = -1;
    std::uint64_t n = 1;
    double value = 0;  // fixed coordinates
};

// The three axes of the mesh, slowest first: the data's axes, then as many fixed
// coordinates as a 3-D mesh lacks, each in its place among the coordinates.
std::vector<MeshAxis> mesh_axes(const ResultInfo& info)
{
    std::vector<MeshAxis> axes;
    for (std::size_t k = 0; k < info.axis_names.size(); ++k) {
        axes.push_back({info.axis_names[k], static_cast<int>(k), info.shape[k], 0});
    }
    const std::vector<std::string> order = info.coordinate_system == "canonical"
                                               ? std::vector<std::string>{"xi", "U", "W"}
                                               : std::vector<std::string>{"x", "u", "v", "omega"};
    const auto rank = [&](const std::string& n) {
        const auto it = std::find(order.begin(), order.end(), n);
        return it == order.end() ? -1 : static_cast<int>(it - order.begin());
    };
    for (const auto& fixed : info.fixed) {
        if (axes.size() == 3) break;
        // Before the first data axis that is a coordinate coming after it.
        const int after = rank(fixed.first);
        auto at = std::find_if(axes.begin(), axes.end(), [&](const MeshAxis& a) { return rank(a.name) > after; });
        axes.insert(at, {fixed.first, -1, 1, fixed.second});
    }
    return axes;
}

}  // namespace

std::string xdmf_unsupported(const std::filesystem::path& result, const ResultInfo& info)
{
    // XDMF names a dataset FILE:PATH with no way to escape a colon in FILE: the legacy
    // reader splits at the first and last colons, the Xdmf3 readers abort pvpython.
    if (result.filename().string().find(':') != std::string::npos) return "XDMF cannot name a file whose name has a colon";
    if (layout::sidecar_path(result) == result) return "the result's own name ends in .xmf";
    if (mesh_axes(info).size() != 3) return "XDMF has no mesh for a result of more than 3 axes";
    return "";
}

std::filesystem::path write_xdmf(const std::filesystem::path& result, const ResultInfo& info)
{
    if (!xdmf_unsupported(result, info).empty()) return {};
    const std::vector<MeshAxis> axes = mesh_axes(info);
    std::filesystem::path out = layout::sidecar_path(result);  // returned: not const, so it moves
    const std::string h5 = xml_escape(result.filename().string());
    const std::string mesh_dims = fmt::format("{} {} {}", axes[0].n, axes[1].n, axes[2].n);

    auto f = fmt::output_file(out.string());
    f.print("<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n <Domain>\n");
    f.print("  <Grid Name=\"{}\" GridType=\"Uniform\">\n", xml_escape(result.stem().string()));
    f.print("   <Topology TopologyType=\"3DRectMesh\" Dimensions=\"{}\"/>\n", mesh_dims);
    f.print("   <Geometry GeometryType=\"VXVYVZ\">\n");
    // X varies fastest: the last axis.
    for (std::size_t k = 3; k-- > 0;) {
        const MeshAxis& a = axes[k];
        if (a.data_axis >= 0) {
            f.print("    <DataItem Name=\"{0}\" Dimensions=\"{1}\" NumberType=\"Float\" Precision=\"8\" "
                    "Format=\"HDF\">{2}:/{0}</DataItem>\n",
                    xml_escape(a.name), a.n, h5);
        } else {
            f.print("    <DataItem Name=\"{}\" Dimensions=\"1\" NumberType=\"Float\" Precision=\"8\" "
                    "Format=\"XML\">{}</DataItem>\n",
                    xml_escape(a.name), fmt::format("{}", a.value));
        }
    }
    f.print("   </Geometry>\n");
    // The data are declared with the mesh's dimensions, which have the same points in the
    // same order as the file's (the thin dimensions have one sample). A Function or
    // HyperSlab item that reshaped them would be exact, but the Xdmf3 readers of ParaView
    // 5.11 cannot read such items as attributes ("Skipping unrecognized array type"): they
    // take the type of an array before reading it. The legacy reader reads the whole
    // dataset by its number of points; reading pieces of a 2-D result (ParaView in
    // parallel, the reader's Stride) it selects a hyperslab of the mesh's rank in the
    // file's and fails, saying so (docs/format.md: ParaView).
    const std::string count_type = info.max_bounces > std::numeric_limits<std::int32_t>::max() ? "8" : "4";
    for (const auto& [name, precision] : {std::pair{"wall_bounces", count_type}, std::pair{"outcome", std::string("4")}}) {
        f.print("   <Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Node\">\n", name);
        f.print("    <DataItem Dimensions=\"{}\" NumberType=\"Int\" Precision=\"{}\" Format=\"HDF\">{}:/{}</DataItem>\n",
                mesh_dims, precision, h5, name);
        f.print("   </Attribute>\n");
    }
    f.print("  </Grid>\n </Domain>\n</Xdmf>\n");
    return out;
}

}  // namespace superball
