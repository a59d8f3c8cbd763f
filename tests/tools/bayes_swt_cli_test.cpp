// `mcdenoise denoise|diff --method bayes --bayes-transform swt` run as a subprocess: the
// plan names the transform, the output is the in-process method's, `diff` runs every stage
// against the reference, bad values are refused. Small frames: every run starts Vulkan.
#include <gtest/gtest.h>

#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

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

class BayesSwtCli : public GpuTest {
  protected:
    ToolResult Run(const std::string &args) { return tool.Run(args); }
    ToolDir tool{"mcd_bayes_swt_cli"};
};

TEST_F(BayesSwtCli, DenoiseDiffAndErrors) {
    const int w = 23, h = 14;
    Image color = MakeInput(InputKind::LogNormalFireflies, w, h, 3, SeedFromName("swt cli"));
    for (float &v : color.data) v = std::min(v, 50.f) * 0.1f;
    io::WriteExr(tool.Path("c.exr").string(), {{"color", &color}});
    ToolResult r =
        Run("denoise c.exr -o out.exr --method bayes --explain --bayes-transform swt "
            "--bayes-wavelet cdf97 --noise fixed");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "3-level cdf97 stationary (undecimated) wavelet transform"))
        << r.out;
    BayesParams options = PaperBayesParams();
    options.basis = WaveletBasis::Cdf97;
    options.transform = BayesTransform::Swt;
    options.restoreZeros = BayesParams().restoreZeros;  // the CLI's defaults
    options.meanRadius = BayesParams().meanRadius;
    Image expected = BayesDenoise(Ctx(), color, options).image;
    EXPECT_TRUE(BitIdentical(expected, io::ReadImage(tool.Path("out.exr").string())));
    r = Run("denoise c.exr -o dwt.exr --method bayes --explain --bayes-transform dwt");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "haar DWT (--bayes-transform dwt)")) << r.out;

    // diff: the stages of the DWT run, the analysis being the SWT's planes. Bounds: the
    // float analysis and moments are within tens of u per element (per pass 11 u, 2 passes
    // per level: BayesSwtKernel), NMSE under (100 u)^2 ~ 4e-11; the fits as the DWT's
    // (CliTest.DiffBayesStages, 1e-9); from the shrinkage on, the whole-method tolerance of
    // BayesSwtMethodWhole.MatchesReference (2e-3 in log), squared.
    r = Run("diff c.exr --method bayes --bayes-transform swt --noise mad");
    ASSERT_EQ(r.code, 0) << r.All();
    std::vector<DiffRow> stages = ParseDiffTable(r.out);
    std::vector<std::string> names;
    for (const DiffRow &row : stages) names.push_back(row.stage);
    ASSERT_EQ(names, (std::vector<std::string>{"log", "analysis", "moments", "fits",
                                               "shrinkage", "synthesis", "exp", "local mean"}))
        << r.out;
    std::map<std::string, double> bound = {
        {"log", 4e-11}, {"analysis", 4e-11}, {"moments", 4e-11},
        {"fits", 1e-9}, {"shrinkage", 4e-6}, {"synthesis", 4e-6},
        {"exp", 4e-6},  {"local mean", 4e-6}};  // exp's error times a ratio of local means
    for (const DiffRow &row : stages)
        EXPECT_LT(row.nmse, bound[row.stage]) << row.stage << "\n" << r.out;

    r = Run("denoise c.exr -o o.exr --method bayes --bayes-transform fft");
    EXPECT_EQ(r.code, int(tool::ExitStatus::Usage));
    EXPECT_TRUE(Contains(r.err, "--bayes-transform: 'fft' is none of its choices (swt or dwt)"))
        << r.err;
    // The help wraps its lines: compare with the spaces and line breaks squeezed.
    r = Run("denoise --help");
    std::string help = std::regex_replace(r.out, std::regex("\\s+"), " ");
    EXPECT_TRUE(Contains(help, "swt (stationary, undecimated: shift-invariant; the default"))
        << r.out;
    EXPECT_GT(help.find("swt (stationary"), help.find("Method bayes:")) << r.out;
}

}  // namespace
}  // namespace mcd::test
