// The XDMF sidecar (io/xdmf.hpp) as written, without ParaView (tests/paraview reads it with
// ParaView's own readers): a 2-D slice sits in the 3-D mesh at its fixed coordinate with its
// axes in coordinate order, X fastest; the data are named by the result's file name alone;
// names XML cannot hold are escaped; what XDMF cannot describe gets no sidecar, and says why.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "io/xdmf.hpp"
#include "../temp_dir.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

std::string text_of(const fs::path& p)
{
    std::ifstream in(p);
    return {std::istreambuf_iterator<char>(in), {}};
}

// A (xi, W) slice at U = -1, 40 x 24 samples.
ResultInfo slice()
{
    ResultInfo info;
    info.coordinate_system = "canonical";
    info.axis_names = {"xi", "W"};
    info.fixed = {{"U", -1.0}};
    info.shape = {40, 24};
    info.max_bounces = 1000;
    return info;
}

TEST(Xdmf, ASliceSitsInTheVolumeAtItsFixedCoordinate)
{
    const test_support::TempDir dir("superball-xdmf");
    const fs::path result = dir / "slice.h5";
    const fs::path xmf = write_xdmf(result, slice());
    ASSERT_EQ(xmf, dir / "slice.xmf");
    const std::string x = text_of(xmf);
    // Z = xi (the data's first axis), Y = U (one sample, at -1), X = W (fastest).
    EXPECT_NE(x.find("<Topology TopologyType=\"3DRectMesh\" Dimensions=\"40 1 24\"/>"), std::string::npos) << x;
    const auto w = x.find("<DataItem Name=\"W\" Dimensions=\"24\""), u = x.find("<DataItem Name=\"U\" Dimensions=\"1\""),
               xi = x.find("<DataItem Name=\"xi\" Dimensions=\"40\"");
    ASSERT_NE(w, std::string::npos) << x;
    ASSERT_NE(u, std::string::npos) << x;
    ASSERT_NE(xi, std::string::npos) << x;
    EXPECT_LT(w, u);
    EXPECT_LT(u, xi);
    EXPECT_NE(x.find("Format=\"XML\">-1</DataItem>"), std::string::npos) << x;
    // The file by its name alone, so the pair can move together.
    EXPECT_NE(x.find(">slice.h5:/wall_bounces</DataItem>"), std::string::npos) << x;
    EXPECT_NE(x.find(">slice.h5:/outcome</DataItem>"), std::string::npos) << x;
    EXPECT_NE(x.find(">slice.h5:/xi</DataItem>"), std::string::npos) << x;
    EXPECT_EQ(x.find(dir / ""), std::string::npos) << "a directory in the sidecar";
    // Counts signed, so that interpolation cannot wrap around zero; 4 bytes hold max_bounces.
    EXPECT_NE(x.find("Dimensions=\"40 1 24\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">slice.h5:/wall_bounces"),
              std::string::npos)
        << x;
}

TEST(Xdmf, NamesAreEscapedAndWhatXdmfCannotHoldIsSaid)
{
    EXPECT_EQ(xml_escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
    const test_support::TempDir dir("superball-xdmf");
    const fs::path odd = dir / "R&D <1>.h5";
    const fs::path xmf = write_xdmf(odd, slice());
    ASSERT_FALSE(xmf.empty());
    EXPECT_NE(text_of(xmf).find(">R&amp;D &lt;1&gt;.h5:/outcome<"), std::string::npos) << text_of(xmf);

    EXPECT_EQ(xdmf_unsupported(dir / "a.h5", slice()), "");
    EXPECT_NE(xdmf_unsupported(dir / "a:b.h5", slice()).find("colon"), std::string::npos);
    EXPECT_TRUE(write_xdmf(dir / "a:b.h5", slice()).empty());
    EXPECT_FALSE(fs::exists(dir / "a:b.xmf"));
    EXPECT_NE(xdmf_unsupported(dir / "a.xmf", slice()).find(".xmf"), std::string::npos);
    ResultInfo physical4;
    physical4.coordinate_system = "physical";
    physical4.axis_names = {"x", "u", "v", "omega"};
    physical4.shape = {4, 5, 6, 7};
    EXPECT_NE(xdmf_unsupported(dir / "p.h5", physical4).find("more than 3 axes"), std::string::npos);
    EXPECT_TRUE(write_xdmf(dir / "p.h5", physical4).empty());
    EXPECT_FALSE(fs::exists(dir / "p.xmf"));
}

}  // namespace
}  // namespace superball
