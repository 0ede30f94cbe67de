#include "xdmf.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

namespace superball {

std::filesystem::path write_xdmf(const std::filesystem::path& result, const ResultInfo& info)
{
    const std::size_t d = info.shape.size();
    if (d < 2 || d > 3) return {};
    std::filesystem::path out = result;
    out.replace_extension(".xmf");
    // Referenced by name: the sidecar stays valid when both files move together.
    const std::string h5 = result.filename().string();
    std::string dims;
    for (const auto n : info.shape) dims += fmt::format("{} ", n);
    dims.pop_back();
    const char* topology = d == 2 ? "2DRectMesh" : "3DRectMesh";
    const char* geometry = d == 2 ? "VXVY" : "VXVYVZ";
    const std::string count_type = info.max_bounces > 65535 ? "Precision=\"4\"" : "Precision=\"2\"";

    auto f = fmt::output_file(out.string());
    f.print("<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n <Domain>\n");
    f.print("  <Grid Name=\"superball\" GridType=\"Uniform\">\n");
    f.print("   <Topology TopologyType=\"{}\" Dimensions=\"{}\"/>\n", topology, dims);
    f.print("   <Geometry GeometryType=\"{}\">\n", geometry);
    // XDMF's X varies fastest: the last axis of the dataset.
    for (std::size_t k = d; k-- > 0;) {
        f.print("    <DataItem Name=\"{}\" Dimensions=\"{}\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{}:/axes/{}</DataItem>\n",
                info.axis_names[k], info.shape[k], h5, info.axis_names[k]);
    }
    f.print("   </Geometry>\n");
    f.print("   <Attribute Name=\"wall_bounces\" AttributeType=\"Scalar\" Center=\"Node\">\n");
    f.print("    <DataItem Dimensions=\"{}\" NumberType=\"UInt\" {} Format=\"HDF\">{}:/wall_bounces</DataItem>\n", dims,
            count_type, h5);
    f.print("   </Attribute>\n");
    f.print("   <Attribute Name=\"outcome\" AttributeType=\"Scalar\" Center=\"Node\">\n");
    f.print("    <DataItem Dimensions=\"{}\" NumberType=\"UChar\" Precision=\"1\" Format=\"HDF\">{}:/outcome</DataItem>\n",
            dims, h5);
    f.print("   </Attribute>\n  </Grid>\n </Domain>\n</Xdmf>\n");
    return out;
}

}  // namespace superball
