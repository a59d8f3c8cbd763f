// `mcdenoise denoise --method bayes` run as a subprocess (MCD_TOOL_PATH): the split and
// no-split plans, warnings with counts on NaN/zero pixels, the output against the method
// called in process, option errors. Small frames: every run starts Vulkan.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "harness/bayes_paper.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "harness/tool.h"
#include "host/io/frame.h"
#include "host/methods/bayes.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

using Output = ToolResult;

class BayesCli : public GpuTest {
  protected:
    Output Run(const std::string &args) { return tool.Run(args); }
    ToolDir tool{"mcd_bayes_cli"};
    const fs::path &dir = tool.Dir();
};

Image Positive(int w, int h, uint64_t seed) {
    Image image = MakeInput(InputKind::LogNormalFireflies, w, h, 3, seed);
    for (float &v : image.data) v = std::min(v, 50.f) * 0.1f;
    return image;
}

TEST_F(BayesCli, SplitAndWholePlansAndTheSameImageAsInProcess) {
    const int w = 29, h = 17;
    Image direct = Positive(w, h, SeedFromName("cli direct")),
          indirect = Positive(w, h, SeedFromName("cli indirect"));
    Image color(w, h, 3);
    for (size_t i = 0; i < color.Size(); ++i) color.data[i] = direct.data[i] + indirect.data[i];
    indirect.At(1, 2, 3) = 0;  // a zero pixel: counted, denoised (--zeros denoise)
    indirect.At(2, 5, 6) = std::numeric_limits<float>::quiet_NaN();
    io::WriteExr((dir / "split.exr").string(),
                 {{"color", &color}, {"direct", &direct}, {"indirect", &indirect}});
    io::WriteExr((dir / "plain.exr").string(), {{"color", &color}});

    Output r =
        Run("denoise split.exr -o out.exr --method bayes --explain --noise fixed --sn 0.3 "
            "--non-finite zero");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "split (section 4.1)")) << r.out;
    EXPECT_TRUE(Contains(r.out, "s_n 0.3")) << r.out;
    EXPECT_TRUE(Contains(r.err,
                         "layer 'indirect' of split.exr has 1 NaN/Inf value, the first "
                         "at pixel (6, 5), channel 2: replaced by 0"))
        << r.err;
    // One line for the black values, the NaN among them now; the layer bayes ran on named.
    EXPECT_TRUE(Contains(r.err, "bayes (indirect layer): ")) << r.err;
    EXPECT_TRUE(Contains(r.err, "the 2 black ones too (--zeros denoise)")) << r.err;
    BayesParams options = PaperBayesParams();
    options.sn = 0.3f;
    options.transform = BayesTransform::Swt;  // the CLI's defaults
    options.restoreZeros = BayesParams().restoreZeros;
    options.meanRadius = BayesParams().meanRadius;
    // The CLI's --non-finite zero: the NaN read as 0, which --zeros denoise then denoises.
    Image zeroed = indirect;
    zeroed.At(2, 5, 6) = 0;
    Image expected = BayesDenoiseSplit(Ctx(), direct, zeroed, options).image;
    EXPECT_TRUE(BitIdentical(expected, io::ReadImage((dir / "out.exr").string())));

    r = Run("denoise split.exr -o whole.exr --method bayes --explain --no-split");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "no split (--no-split)")) << r.out;
    r =
        Run("denoise plain.exr -o plain_out.exr --method bayes --explain --noise auto "
            "--bayes-wavelet cdf97 --bayes-levels 2");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "the frame has no direct and indirect layers")) << r.out;
    EXPECT_TRUE(Contains(r.out, "--noise auto")) << r.out;
    EXPECT_TRUE(Contains(r.out, "2-level cdf97")) << r.out;
    Image out = io::ReadImage((dir / "plain_out.exr").string());
    for (float v : out.data) EXPECT_TRUE(std::isfinite(v));
}

// --noise auto takes the variance layer when there is one (and says so), the MAD estimate
// otherwise; the output is the in-process method's with the layer.
TEST_F(BayesCli, NoiseAutoUsesTheVarianceLayer) {
    const int w = 21, h = 13;
    Image color = Positive(w, h, SeedFromName("cli variance color"));
    Image variance(w, h, 3);
    for (size_t i = 0; i < color.Size(); ++i)
        variance.data[i] = 0.04f * color.data[i] * color.data[i];
    io::WriteExr((dir / "v.exr").string(), {{"color", &color}, {"variance", &variance}});
    Output r = Run("denoise v.exr -o out.exr --method bayes --explain --noise auto");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "the frame has a variance layer")) << r.out;
    EXPECT_TRUE(Contains(r.out, "--noise variance: per band")) << r.out;
    BayesParams options = PaperBayesParams();
    options.noise = BayesNoise::Variance;
    options.transform = BayesTransform::Swt;  // the CLI's defaults
    options.restoreZeros = BayesParams().restoreZeros;
    options.meanRadius = BayesParams().meanRadius;
    Image expected = BayesDenoise(Ctx(), color, options, {}, &variance).image;
    EXPECT_TRUE(BitIdentical(expected, io::ReadImage((dir / "out.exr").string())));
    io::WriteExr((dir / "c.exr").string(), {{"color", &color}});
    r = Run("denoise c.exr -o out2.exr --method bayes --explain --noise auto");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "no variance layer")) << r.out;
    EXPECT_TRUE(Contains(r.out, "finest HH bands' median")) << r.out;
}

// --zeros restore on our interior at 4 spp, whose indirect light half the pixels' samples
// miss (issue 29's black holes): bayes refuses it, naming the layer, the counts and --zeros
// denoise, and writes nothing; auto with the same setting leaves bayes out and runs the
// others.
TEST_F(BayesCli, RestoreRefusesDenseZerosAndAutoRunsWithout) {
    Output r = Run("render --scene interior --spp 4 --size 32x32 --layers all -o dense.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    r = Run("denoise dense.exr -o refused.exr --method bayes --zeros restore");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument));
    EXPECT_TRUE(Contains(r.err, "bayes (indirect layer): --zeros restore refused")) << r.err;
    EXPECT_TRUE(Contains(r.err, "of the 3072 values would stay black")) << r.err;
    EXPECT_TRUE(Contains(r.err, "use --zeros denoise")) << r.err;
    EXPECT_FALSE(fs::exists(dir / "refused.exr"));
    r = Run("denoise dense.exr -o denoised.exr --method bayes --zeros denoise");
    EXPECT_EQ(r.code, 0) << r.err;
    r = Run("denoise dense.exr -o auto.exr --method auto --zeros restore --explain");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out,
                         "auto: left out bayes: bayes (indirect layer): --zeros restore "
                         "refused"))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "auto: ran ")) << r.out;
    EXPECT_TRUE(fs::exists(dir / "auto.exr"));
    // With bayes its only candidate, auto fails saying why bayes was left out.
    r =
        Run("denoise dense.exr -o none.exr --method auto --auto-candidates bayes "
            "--zeros restore");
    EXPECT_EQ(r.code, int(tool::ExitStatus::InvalidArgument)) << r.err;
    EXPECT_TRUE(Contains(r.err,
                         "found no method for this frame (first left out: bayes: bayes "
                         "(indirect layer): --zeros restore refused"))
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "none.exr"));
}

TEST_F(BayesCli, OptionErrors) {
    Image color = Positive(8, 8, 1);
    io::WriteExr((dir / "f.exr").string(), {{"color", &color}});
    // A value none of an option's choices names is a command line error, as one out of range.
    Output r = Run("denoise f.exr -o o.exr --method bayes --noise maybe");
    EXPECT_EQ(r.code, int(tool::ExitStatus::Usage));
    EXPECT_TRUE(Contains(r.err,
                         "--noise: 'maybe' is none of its choices (auto, fixed, mad or "
                         "variance)"))
        << r.err;
    r = Run("denoise f.exr -o o.exr --method bayes --noise variance");
    EXPECT_EQ(r.code, int(tool::ExitStatus::MissingLayer));
    EXPECT_TRUE(Contains(r.err, "--noise variance needs a variance layer")) << r.err;
    r = Run("denoise f.exr -o o.exr --method bayes --bayes-wavelet db4");
    EXPECT_EQ(r.code, int(tool::ExitStatus::Usage));
    EXPECT_TRUE(Contains(r.err, "'db4' is none of its choices (haar, legall53 or cdf97)"))
        << r.err;
    r = Run("denoise f.exr -o o.exr --method bayes --pn 0");
    EXPECT_NE(r.code, 0);
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
    r = Run("denoise --help");
    EXPECT_TRUE(Contains(r.out, "noise s_n")) << r.out;
    EXPECT_GT(r.out.find("noise s_n"), r.out.find("\nMethod bayes:\n")) << r.out;
}

// `bench bayes` takes the method's own parameters, not flags of its own.
TEST_F(BayesCli, BenchTakesTheMethodsParameters) {
    Output r =
        Run("bench bayes --size 32x24 --repeat 1 --no-skimage --bayes-transform dwt "
            "--bayes-levels 2 --noise fixed");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "32x24 RGB float32, 2 levels of haar dwt, noise fixed"))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "bayes.shrink")) << r.out;
    EXPECT_TRUE(Contains(r.out, "GPU total")) << r.out;
    r = Run("bench bayes --size 32x24 --levels 2");
    EXPECT_NE(r.code, 0);
}

}  // namespace
}  // namespace mcd::test
