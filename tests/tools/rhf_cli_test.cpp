// `mcdenoise denoise --method rhf` end to end: a rendered frame with histograms in, a
// denoised frame out, the plan, errors on frames without histograms, and frames from
// another renderer in the authors' channel layout.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "harness/tool.h"
#include "host/image.h"
#include "host/io/frame.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

// Stdout and stderr together: the tests look for messages wherever they are printed.
struct Ran {
    int code = -1;
    std::string out;
};

class RhfCli : public ::testing::Test {
  protected:
    Ran Run(const std::string &args) {
        ToolResult r = tool.Run(args);
        return {r.code, r.out + r.err};
    }
    std::string Path(const std::string &name) const { return tool.Path(name).string(); }
    static bool Has(const std::string &text, const std::string &part) {
        return text.find(part) != std::string::npos;
    }
    ToolDir tool{"mcd_rhf_cli"};
};

TEST_F(RhfCli, DenoisesARenderedFrame) {
    ASSERT_EQ(Run("render --scene cornell --size 32x28 --spp 4 --layers hist -o n.exr").code,
              0);
    ASSERT_EQ(Run("render --scene cornell --size 32x28 --spp 64 --seed 7 -o r.exr").code, 0);
    Ran r = Run("denoise n.exr --method rhf --nscales 2 --explain -o d.exr --reference r.exr");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(Has(r.out, "chi-square pixel terms")) << r.out;
    EXPECT_TRUE(Has(r.out, "with bright veto 0.3")) << r.out;
    EXPECT_TRUE(Has(r.out, "u_0 - U(D(u_0)) + U(u_1)")) << r.out;
    EXPECT_TRUE(Has(r.out, "PSNR")) << r.out;
    Image out = io::ReadImage(Path("d.exr"));
    EXPECT_EQ(out.width, 32);
    for (float v : out.data) ASSERT_TRUE(std::isfinite(v));
    // Options reach the method: one scale requested, none left out.
    r =
        Run("denoise n.exr --method rhf --nscales 1 --kappa 0.5 --knn 3 --patch-half 2 "
            "--search-half 4 --bright-veto 0 --explain -o e.exr");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_FALSE(Has(r.out, "scale 1")) << r.out;
    EXPECT_TRUE(Has(r.out, "(no bright veto)")) << r.out;
    EXPECT_TRUE(Has(r.out, "5x5 patch distances")) << r.out;
    EXPECT_TRUE(Has(r.out, "81 offsets")) << r.out;
    // Every stage against the CPU reference: float32 against double gives NMSE ~1e-14
    // here (max relative error ~3e-7); a stage off by 1% would be ~1e-4.
    r = Run("diff n.exr --method rhf --nscales 2 --max-nmse 1e-9");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(Has(r.out, "filtered s1")) << r.out;
    EXPECT_TRUE(Has(r.out, "combined s0")) << r.out;
    // A frame without histograms is refused, naming what is missing.
    ASSERT_EQ(Run("render --size 8x8 --spp 2 -o bare.exr").code, 0);
    r = Run("denoise bare.exr --method rhf -o f.exr");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Has(r.out, "Bin_0000")) << r.out;
    EXPECT_FALSE(fs::exists(Path("f.exr")));
}

// Another renderer's file in the authors' layout: Bin_NNNN channels only next to the RGB
// colour, here with 8 bins and a NaN colour, reads as histograms; the NaN is refused, or
// replaced with a warning.
// `bench rhf` takes the method's own parameters and times every kernel.
TEST_F(RhfCli, BenchTakesTheMethodsParameters) {
    Ran r = Run("bench rhf --size 24x20 --spp 2 --kappa 0.6 --nscales 1");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(Has(r.out, "24x20 at 2 spp, patch half 1, search half 6, kappa 0.6")) << r.out;
    EXPECT_TRUE(Has(r.out, "1 scales")) << r.out;
    EXPECT_TRUE(Has(r.out, "rhf.terms")) << r.out;
    EXPECT_FALSE(Has(r.out, "rhf.combine")) << r.out;
    EXPECT_NE(Run("bench rhf --size 24x20 --kappa -1").code, 0);
}

TEST_F(RhfCli, ReadsOtherRenderersLayoutAndWarns) {
    const int w = 16, h = 12, n = 8;
    Image color(w, h, 3), hist(w, h, 3 * n + 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int bin = (x / 4) % n;
            for (int c = 0; c < 3; ++c) {
                color.At(c, y, x) = 0.1f * float(bin + 1);
                hist.At(c * n + bin, y, x) = 6;
            }
            hist.At(3 * n, y, x) = 6;
        }
    color.At(1, 3, 3) = std::nanf("");
    io::WriteExr(Path("other.exr"), {{"color", &color}, {"hist", &hist}});
    Ran r = Run("denoise other.exr --method rhf -o d.exr");  // refused by default
    EXPECT_NE(r.code, 0) << r.out;
    EXPECT_TRUE(Has(r.out,
                    "layer 'color' of other.exr has 1 NaN/Inf value, the first at pixel "
                    "(3, 3), channel 1"))
        << r.out;
    r = Run("denoise other.exr --method rhf --non-finite zero -o d.exr");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(Has(r.out, "replaced by 0 (--non-finite zero)")) << r.out;
    for (float v : io::ReadImage(Path("d.exr")).data) ASSERT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace mcd::test
