// `render --tracing-filter`: the frame keeps the plain color as color.unfiltered beside the
// usual layers, the CPU and GPU gathers agree, denoise takes the frame, bad use is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "harness/tool.h"
#include "host/io/frame.h"

namespace mcd::test {
namespace {

TEST(CliTracingFilter, WritesFilteredAndUnfilteredColor) {
    ToolDir dir("mcd-tf-cli");
    const std::string render =
        "render --scene relief-abc --size 20x14 --spp 2 --layers split,partials";
    ToolResult gpu = dir.Run(render + " --tracing-filter --tf-radius 2 -o gpu.exr");
    ASSERT_EQ(gpu.code, 0) << gpu.All();
    EXPECT_NE(gpu.out.find("tracing filter (GPU gather,"), std::string::npos) << gpu.out;
    EXPECT_NE(gpu.out.find("records peak"), std::string::npos) << gpu.out;
    ToolResult cpu = dir.Run(render + " --tracing-filter --tf-radius 2 --tf-cpu -o cpu.exr");
    ASSERT_EQ(cpu.code, 0) << cpu.All();
    ASSERT_EQ(dir.Run(render + " -o plain.exr").code, 0);
    io::Frame g = io::ReadFrame(dir.Path("gpu.exr").string()),
              c = io::ReadFrame(dir.Path("cpu.exr").string()),
              p = io::ReadFrame(dir.Path("plain.exr").string());
    for (const auto &[name, image] : p.layers) ASSERT_TRUE(g.layers.count(name)) << name;
    const Image &unfiltered = g.Get("color.unfiltered"), &plain = p.Get("color");
    ASSERT_EQ(unfiltered.data, plain.data);
    const Image &a = g.Get("color"), &b = c.Get("color");
    double moved = 0;
    for (size_t i = 0; i < a.Size(); ++i) {
        EXPECT_NEAR(a.data[i], b.data[i], 1e-4f * (1 + std::fabs(b.data[i])));
        moved += std::fabs(a.data[i] - plain.data[i]);
    }
    EXPECT_GT(moved, 0);
    EXPECT_EQ(g.metadata.count("mcd:tracingFilter"), 1u);
    // The image methods take the filtered frame as any other.
    ToolResult denoised = dir.Run("denoise --method awr gpu.exr -o d.exr");
    EXPECT_EQ(denoised.code, 0) << denoised.All();
}

TEST(CliTracingFilter, BadUseIsRefused) {
    ToolDir dir("mcd-tf-cli");
    ToolResult r = dir.Run("render --size 8x8 --tracing-filter --reference -o r.exr");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.All().find("--tracing-filter"), std::string::npos) << r.All();
    r = dir.Run("render --size 8x8 --tracing-filter --tf-radius -2 -o r.exr");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.All().find("--tf-radius"), std::string::npos) << r.All();
    r = dir.Run("render --size 8x8 --tracing-filter --tf-partials 3 -o r.exr");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.All().find("--tf-partials"), std::string::npos) << r.All();
    EXPECT_FALSE(std::filesystem::exists(dir.Path("r.exr")));
}

// --tf-partials: 1 leaves the light seen in a mirror (partial 1) as rendered, the default
// (2) filters it too; partial 0 and the unfiltered colour are the same either way.
TEST(CliTracingFilter, PartialsOption) {
    ToolDir dir("mcd-tf-cli");
    const std::string render =
        "render --scene glossy-cornell --size 16x12 --spp 2 --layers partials --tracing-filter";
    ASSERT_EQ(dir.Run(render + " --tf-partials 1 -o one.exr").code, 0);
    ToolResult two = dir.Run(render + " -o two.exr");
    ASSERT_EQ(two.code, 0) << two.All();
    ASSERT_EQ(dir.Run("render --scene glossy-cornell --size 16x12 --spp 2 --layers partials "
                      "-o plain.exr")
                  .code,
              0);
    io::Frame a = io::ReadFrame(dir.Path("one.exr").string()),
              b = io::ReadFrame(dir.Path("two.exr").string()),
              p = io::ReadFrame(dir.Path("plain.exr").string());
    EXPECT_EQ(a.Get("partial1.color").data, p.Get("partial1.color").data);
    EXPECT_NE(b.Get("partial1.color").data, p.Get("partial1.color").data);
    EXPECT_EQ(a.Get("partial0.color").data, b.Get("partial0.color").data);
    EXPECT_EQ(a.Get("color.unfiltered").data, b.Get("color.unfiltered").data);
    EXPECT_NE(b.metadata.at("mcd:tracingFilter").find("partials 2 of 2"), std::string::npos);
    // A scene without a mirror filters partial 0 only: no records, no gather for the rest.
    ToolResult relief =
        dir.Run("render --scene relief-abc --size 16x12 --spp 2 --tracing-filter -o r.exr");
    ASSERT_EQ(relief.code, 0) << relief.All();
    EXPECT_NE(relief.out.find("1 partial image(s), the scene has no mirror"), std::string::npos)
        << relief.out;
    EXPECT_NE(io::ReadFrame(dir.Path("r.exr").string())
                  .metadata.at("mcd:tracingFilter")
                  .find("partials 1 of 2"),
              std::string::npos);
}

}  // namespace
}  // namespace mcd::test
