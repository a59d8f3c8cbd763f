// The mcdenoise command-line tool, run as a subprocess (MCD_TOOL_PATH) in a temporary
// directory: help texts, `info`, `wavelet` (round trip, band dumps checked against the CPU
// reference, PNG output, the built-in image), error messages and exit codes, no partial or
// clobbered outputs after a failure, the placeholder commands and `bench wavelet`.
// Small images only: every run starts Vulkan (~0.3 s on lavapipe).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bayes/bayes.h"
#include "cpu_reference/wavelet_analyze.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/inputs.h"
#include "harness/tool.h"
#include "host/image.h"
#include "host/io/frame.h"
#include "host/metrics.h"
#include "host/vk/context.h"
#include "host/wavelet.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

using RunResult = ToolResult;

std::string ReadBytes(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A failure reported by main(): the exit status of its kind, stderr starting with
// "mcdenoise: error:" and naming the problem.
::testing::AssertionResult IsError(const RunResult &r, ErrorKind kind,
                                   const std::string &part) {
    int expected = int(tool::StatusOf(kind));
    if (r.code != expected)
        return ::testing::AssertionFailure()
               << "exit code " << r.code << ", expected " << expected << " ("
               << ErrorKindName(kind) << "); output:\n"
               << r.All();
    if (r.err.rfind("mcdenoise: error:", 0) != 0)
        return ::testing::AssertionFailure()
               << "stderr does not start with 'mcdenoise: error:':\n"
               << r.err;
    return Contains(r.err, part);
}

// The names in a directory (not recursive).
std::set<std::string> Listing(const fs::path &dir) {
    std::set<std::string> names;
    for (const fs::directory_entry &e : fs::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

class CliTest : public ::testing::Test {
  protected:
    RunResult Run(const std::string &args, const std::string &env = "") {
        return tool.Run(args, env);
    }
    fs::path Path(const std::string &name) const { return tool.Path(name); }

    // A 37x23 RGB input with a variance layer, written as EXR in the temporary directory.
    Image WriteInput(const std::string &name) {
        Image color = MakeInput(InputKind::Uniform, 37, 23, 3, SeedFromName("cli " + name));
        Image variance(37, 23, 1, 0.25f);
        io::WriteExr(Path(name).string(), {{"color", &color}, {"variance", &variance}});
        return color;
    }

    ToolDir tool{"mcd_cli_test"};
};

TEST_F(CliTest, HelpListsCommands) {
    RunResult r = Run("--help");
    ASSERT_EQ(r.code, 0) << r.All();
    for (const char *command : {"info", "wavelet", "bench", "denoise", "render", "diff"})
        EXPECT_TRUE(Contains(r.out, std::string("\n  ") + command + " ")) << command;

    r = Run("wavelet --help");
    ASSERT_EQ(r.code, 0) << r.All();
    for (const char *option :
         {"--basis", "--levels", "--dump", "--device", "--output", "--layer"})
        EXPECT_TRUE(Contains(r.out, option));
}

TEST_F(CliTest, InfoListsDevicesAndLimits) {
    RunResult r = Run("info");
    ASSERT_EQ(r.code, 0) << r.All();
    std::vector<vk::DeviceInfo> devices = vk::ListDevices();
    ASSERT_FALSE(devices.empty());
    for (const vk::DeviceInfo &d : devices) {
        EXPECT_TRUE(Contains(r.out, d.name));
        EXPECT_TRUE(Contains(r.out, std::to_string(d.limits.maxStorageBufferRange) + " bytes"));
    }
    EXPECT_TRUE(Contains(r.out, "maxStorageBufferRange"));
    // Exactly one device is marked as the one used.
    size_t marked = 0;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("* ", 0) == 0) ++marked;
    EXPECT_EQ(marked, 1u) << r.out;
    bool lavapipe = std::any_of(devices.begin(), devices.end(), [](const vk::DeviceInfo &d) {
        return d.name.find("llvmpipe") != std::string::npos;
    });
    if (lavapipe) {
        EXPECT_TRUE(Contains(r.out, "llvmpipe"));
    }
}

TEST_F(CliTest, InfoDescribesFrameLayers) {
    Image color(37, 23, 3, 0.5f);
    color.At(0, 3, 4) = std::numeric_limits<float>::quiet_NaN();
    color.At(1, 10, 30) = std::numeric_limits<float>::quiet_NaN();
    color.At(2, 22, 36) = std::numeric_limits<float>::infinity();
    Image variance(37, 23, 1, 0.25f);
    io::WriteExr(Path("frame.exr").string(), {{"color", &color}, {"variance", &variance}});

    RunResult r = Run("info frame.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "frame.exr: 37x23"));
    std::string colorLine, varianceLine;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
        if (line.find(" color ") != std::string::npos) colorLine = line;
        if (line.find(" variance ") != std::string::npos) varianceLine = line;
    }
    ASSERT_FALSE(colorLine.empty()) << r.out;
    ASSERT_FALSE(varianceLine.empty()) << r.out;
    EXPECT_TRUE(Contains(colorLine, "3 channels"));
    EXPECT_TRUE(Contains(colorLine, "3 non-finite"));
    EXPECT_TRUE(Contains(varianceLine, "1 channel"));
    EXPECT_TRUE(Contains(varianceLine, "mean 0.25"));
    EXPECT_EQ(varianceLine.find("non-finite"), std::string::npos) << varianceLine;
}

// Round trip through the GPU, and every dumped band equal to its crop of the reference's
// coefficient image (level k: HL = high x / low y, LH = low x / high y, HH = both high).
TEST_F(CliTest, WaveletRoundTripAndBandDump) {
    const int levels = 3;
    Image input = WriteInput("in.exr");
    RunResult r = Run("wavelet in.exr -o out.exr --basis legall53 --levels 3 --dump bands");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "3 levels of legall53"));

    Image back = io::ReadImage(Path("out.exr").string());
    ASSERT_TRUE(back.SameShape(input));
    double maxError = 0, maxValue = 0;
    for (size_t i = 0; i < input.Size(); ++i) {
        maxError = std::max(maxError, double(std::fabs(back.data[i] - input.data[i])));
        maxValue = std::max(maxValue, double(std::fabs(input.data[i])));
    }
    EXPECT_LT(maxError, 1e-5 * maxValue);

    Image coef = ref::WaveletAnalyze(input, WaveletBasis::LeGall53, levels);
    Image magnitude = ref::WaveletAnalyzeMagnitude(input, WaveletBasis::LeGall53, levels);
    struct Band {
        std::string name;
        int x0, y0, x1, y1;
    };
    std::vector<Band> bands;
    for (int level = 0; level < levels; ++level) {
        int lw = LevelExtent(input.width, level), lh = LevelExtent(input.height, level);
        int hw = (lw + 1) / 2, hh = (lh + 1) / 2;
        std::string prefix = "L" + std::to_string(level + 1) + "_";
        bands.push_back({prefix + "HL", hw, 0, lw, hh});
        bands.push_back({prefix + "LH", 0, hh, hw, lh});
        bands.push_back({prefix + "HH", hw, hh, lw, lh});
    }
    bands.push_back(
        {"L3_LL", 0, 0, LevelExtent(input.width, levels), LevelExtent(input.height, levels)});
    // L1_HH is x in [19, 37), y in [12, 23) of the 37x23 coefficient image.
    EXPECT_EQ(bands[2].name, "L1_HH");
    EXPECT_EQ(bands[2].x0, 19);
    EXPECT_EQ(bands[2].y0, 12);

    std::set<std::string> expectedFiles;
    for (const Band &band : bands) {
        SCOPED_TRACE(band.name);
        expectedFiles.insert(band.name + ".exr");
        expectedFiles.insert(band.name + ".png");
        fs::path exr = Path("bands") / (band.name + ".exr");
        ASSERT_TRUE(fs::exists(exr));
        Image dumped = io::ReadImage(exr.string());
        Image expected = coef.Crop(band.x0, band.y0, band.x1, band.y1);
        Image scale = magnitude.Crop(band.x0, band.y0, band.x1, band.y1);
        EXPECT_TRUE(ImagesMatch(expected, dumped, scale, {1e-5, 0, 1e-9}));
        Image png = io::ReadImage((Path("bands") / (band.name + ".png")).string());
        EXPECT_EQ(png.width, band.x1 - band.x0);
        EXPECT_EQ(png.height, band.y1 - band.y0);
    }
    EXPECT_EQ(Listing(Path("bands")), expectedFiles);
}

TEST_F(CliTest, WaveletWritesPng) {
    WriteInput("in.exr");
    RunResult r = Run("wavelet in.exr -o out.png --basis haar --levels 2");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(ReadBytes(Path("out.png")).substr(0, 8), "\x89PNG\r\n\x1a\n");
    io::Frame frame = io::ReadFrame(Path("out.png").string());
    EXPECT_EQ(frame.width, 37);
    EXPECT_EQ(frame.height, 23);
    ASSERT_TRUE(frame.Has("color"));
    EXPECT_EQ(frame.Get("color").channels, 3);
}

TEST_F(CliTest, WaveletBuiltinImage) {
    RunResult r = Run("wavelet builtin:rings@64x48 -o r.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "64x48x3"));
    Image image = io::ReadImage(Path("r.exr").string());
    EXPECT_EQ(image.width, 64);
    EXPECT_EQ(image.height, 48);
    EXPECT_EQ(image.channels, 3);
    for (float v : image.data) ASSERT_TRUE(std::isfinite(v));
}

TEST_F(CliTest, ErrorsNameTheProblem) {
    WriteInput("in.exr");
    std::set<std::string> before = Listing(tool.Dir());

    RunResult r = Run("wavelet missing.exr -o out.exr");
    EXPECT_TRUE(IsError(r, ErrorKind::Io, "missing.exr"));
    r = Run("wavelet in.exr --basis db4");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "db4"));
    r = Run("wavelet in.exr --levels 9");  // 37x23 allows 0..6
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "allows 0..6"));
    r = Run("wavelet in.exr --layer nope");
    EXPECT_TRUE(IsError(r, ErrorKind::MissingLayer, "'nope'"));
    EXPECT_TRUE(Contains(r.err, "variance"));  // and the layers the file has
    r = Run("wavelet builtin:squares");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "builtin:squares"));
    r = Run("wavelet builtin:rings@0x5");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "0x5"));
    r = Run("wavelet in.exr --device no-such-gpu");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "no-such-gpu"));
    r = Run("wavelet in.exr --levels 1 -o nodir/out.exr");
    EXPECT_TRUE(IsError(r, ErrorKind::Io, "nodir"));

    // Nothing was written: no output, no temporary files, no directory made.
    EXPECT_EQ(Listing(tool.Dir()), before);

    // Unknown options are CLI11 parse errors.
    r = Run("wavelet in.exr --bogus");
    EXPECT_EQ(r.code, int(tool::ExitStatus::Usage)) << "a parse error, not a run-time one";
    EXPECT_TRUE(Contains(r.All(), "--bogus"));
    r = Run("no-such-command");
    EXPECT_NE(r.code, 0);
    r = Run("");  // no command: the help, as a request for it
    EXPECT_EQ(r.code, 0);
    EXPECT_TRUE(Contains(r.out, "Usage: mcdenoise"));
}

// A failed run never writes over a good output, whether it fails before the GPU work
// (levels, device) or after it (a --dump directory that cannot be made).
TEST_F(CliTest, FailedRunKeepsExistingOutput) {
    WriteInput("in.exr");
    RunResult r = Run("wavelet in.exr -o out.exr --levels 2");
    ASSERT_EQ(r.code, 0) << r.All();
    const std::string good = ReadBytes(Path("out.exr"));
    ASSERT_FALSE(good.empty());
    std::ofstream(Path("afile")) << "not a directory";

    for (const char *args : {"wavelet in.exr -o out.exr --basis cdf97 --levels 7",
                             "wavelet in.exr -o out.exr --device no-such-gpu",
                             "wavelet in.exr -o out.exr --levels 1 --dump afile"}) {
        SCOPED_TRACE(args);
        r = Run(args);
        EXPECT_NE(r.code, 0) << r.All();
        EXPECT_EQ(ReadBytes(Path("out.exr")), good);
    }
    EXPECT_EQ(Listing(tool.Dir()), (std::set<std::string>{"afile", "in.exr", "out.exr"}));
}

// `denoise` reads its frame while the device starts on another thread: a frame whose pixels
// cannot be read is still the error reported, not the device's; a frame that reads, on a
// device that is not there, reports the device; neither writes an output.
TEST_F(CliTest, DenoiseReportsAnUnreadableFrameBeforeTheDevice) {
    Image color = MakeInput(InputKind::Uniform, 37, 23, 3, SeedFromName("cli frame"));
    Image variance(37, 23, 3, 0.25f);
    io::WriteExr(Path("in.exr").string(), {{"color", &color}, {"variance", &variance}});
    const std::string whole = ReadBytes(Path("in.exr"));
    // The header whole, the pixels cut short.
    std::ofstream(Path("cut.exr"), std::ios::binary) << whole.substr(0, whole.size() * 2 / 3);
    RunResult r = Run("denoise cut.exr -o out.exr --method awr --device no-such-gpu");
    EXPECT_TRUE(IsError(r, ErrorKind::Io, "cut.exr"));
    r = Run("denoise in.exr -o out.exr --method awr --device no-such-gpu");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "no-such-gpu"));
    EXPECT_EQ(Listing(tool.Dir()), (std::set<std::string>{"cut.exr", "in.exr"}));
    r = Run("denoise in.exr -o out.exr --method awr");
    EXPECT_EQ(r.code, 0) << r.All();
}

// A --dump path that is an existing file is refused up front, as an error naming it.
TEST_F(CliTest, DumpOntoFileIsAnError) {
    std::ofstream(Path("afile")) << "not a directory";
    RunResult r = Run("wavelet builtin:rings@8x8 --dump afile");
    EXPECT_TRUE(IsError(r, ErrorKind::Io, "afile"));
}

// `diff`: every awr stage on the GPU against the CPU reference, dumped on request. NMSE of
// float32 against double is ~1e-13 here; 1e-9 leaves room and still fails a wrong stage.
TEST_F(CliTest, DiffAwrStages) {
    ASSERT_EQ(Run("render --size 29x17 --spp 4 -o f.exr").code, 0);
    RunResult r = Run("diff f.exr --method awr --dump dd");
    ASSERT_EQ(r.code, 0) << r.All();
    for (const char *stage : {"analysis", "variance analysis", "shrinkage", "synthesis"}) {
        size_t at = r.out.find(std::string("  ") + stage + " ");
        ASSERT_NE(at, std::string::npos) << stage << "\n" << r.out;
        double nmse = std::strtod(r.out.c_str() + at + 2 + std::strlen(stage), nullptr);
        EXPECT_LT(nmse, 1e-9) << stage;
        std::string file = stage;
        std::replace(file.begin(), file.end(), ' ', '-');
        EXPECT_TRUE(fs::exists(Path("dd/" + file + ".gpu.exr"))) << file;
        EXPECT_TRUE(fs::exists(Path("dd/" + file + ".cpu.exr"))) << file;
    }
    EXPECT_TRUE(IsError(Run("diff f.exr --method nope"), ErrorKind::InvalidArgument, "nope"));
    // --max-nmse turns a mismatch into a failure: no float32 stage meets 0 exactly.
    EXPECT_TRUE(IsError(Run("diff f.exr --method awr --max-nmse 0"), ErrorKind::Internal,
                        "--max-nmse"));
    EXPECT_EQ(Run("diff f.exr --method awr --max-nmse 1e-9").code, 0);
    EXPECT_TRUE(
        IsError(Run("diff f.exr --cs 0"), ErrorKind::InvalidArgument, "nothing to compare"));
}

// The rows of `mcdenoise diff`: stage -> (NMSE, max rel error), and the stage order.
struct DiffRows {
    std::vector<std::string> order;
    std::map<std::string, std::pair<double, double>> rows;
};
DiffRows ParseDiff(const std::string &out) {
    DiffRows d;
    for (const DiffRow &row : ParseDiffTable(out)) {
        d.order.push_back(row.stage);
        d.rows[row.stage] = {row.nmse, row.maxRel};
    }
    return d;
}

// `diff --method bayes`: every stage of the GPU run (float32) against the CPU reference
// (double where it matters), with bounds derived stage by stage (u = 2^-24):
// - log, analysis, moments: float rounding of a few to tens of u per element (GLSL log 3
//   ulp; Haar 2 u per level; the moment sums (count/256 + 12) u, and m4 carries 4 times
//   its coefficients' error): relative error under 50 u, NMSE under (50 u)^2 ~ 1e-11.
// - fits (s_c, p_c, fit code): float lgamma is good to about 2^-20 absolute, 6 calls per
//   log kurtosis, moving p_c by that over the slope of log kurtosis (>= 0.2 on the
//   bracket): relative error under 3e-5, NMSE under 1e-9. A fit code that differs (codes
//   are O(1) beside s_c, p_c) would be far above it.
// - shrinkage: the table's interpolation error, at most du^2 (|y| + 4 s_n) per detail
//   coefficient (BayesKernel.TableAndShrinkMatchTheDirectIntegral) with du = asinh(y_max /
//   s_n) / 255; taken at the worst band (largest |y|, smallest s_n) and summed over the
//   dumped coefficients, plus the fits' 1e-9. A worst-case bound: the error is that large
//   only at the table's knee, so it is loose by about 10^3 on this frame.
// - synthesis: orthonormal Haar keeps the error's energy, plus 2 u per level.
// - exp: out (1 + dz) with |dz| <= the synthesis' max rel error times max |z|, plus exp's
//   (3 + 2 |z|) u: NMSE <= max dz^2. split: the same absolute error on a larger image.
TEST_F(CliTest, DiffBayesStages) {
    ASSERT_EQ(Run("render --size 29x17 --spp 4 --layers split -o f.exr").code, 0);
    // The bounds below read the DWT's Mallat layout (the CLI's default is swt), without the
    // local mean (its stage: BayesSwtCli.DenoiseDiffAndErrors).
    RunResult r =
        Run("diff f.exr --method bayes --bayes-transform dwt --bayes-mean-radius 0 --dump db");
    ASSERT_EQ(r.code, 0) << r.All();
    DiffRows d = ParseDiff(r.out);
    const std::vector<std::string> stages = {"log",       "analysis",  "moments", "fits",
                                             "shrinkage", "synthesis", "exp",     "split"};
    ASSERT_EQ(d.order, stages) << r.out;
    const double u = std::ldexp(1.0, -24), sn = 0.19;  // the defaults: 3 Haar levels
    const int levels = 3;
    Image coef = io::ReadImage(Path("db/analysis.cpu.exr").string());
    Image shrunk = io::ReadImage(Path("db/shrinkage.cpu.exr").string());
    Image logOut = io::ReadImage(Path("db/synthesis.cpu.exr").string());
    int lowW = LevelExtent(coef.width, levels), lowH = LevelExtent(coef.height, levels);
    double yMax = 0, maxZ = 0, num = 0, den = 0;
    auto detail = [&](int y, int x) { return x >= lowW || y >= lowH; };
    for (int c = 0; c < coef.channels; ++c)
        for (int y = 0; y < coef.height; ++y)
            for (int x = 0; x < coef.width; ++x)
                if (detail(y, x)) yMax = std::max(yMax, double(std::fabs(coef.At(c, y, x))));
    double du = std::asinh(yMax / sn) / (BAYES_TABLE_SIZE - 1);
    for (int c = 0; c < coef.channels; ++c)
        for (int y = 0; y < coef.height; ++y)
            for (int x = 0; x < coef.width; ++x) {
                if (detail(y, x))
                    num += std::pow(du * du * (std::fabs(coef.At(c, y, x)) + 8 * sn), 2);
                den += double(shrunk.At(c, y, x)) * shrunk.At(c, y, x);
            }
    for (float z : logOut.data) maxZ = std::max(maxZ, double(std::fabs(z)));
    std::map<std::string, double> bound = {
        {"log", 1e-11}, {"analysis", 1e-11}, {"moments", 1e-11}, {"fits", 1e-9}};
    bound["shrinkage"] = num / den + 1e-9;
    bound["synthesis"] = std::pow(std::sqrt(bound["shrinkage"]) + 2 * (levels + 1) * u, 2);
    double dz = d.rows["synthesis"].second * maxZ + (3 + 2 * maxZ) * u;
    bound["exp"] = bound["split"] = dz * dz * 1.01;
    for (const std::string &stage : stages) {
        SCOPED_TRACE(stage);
        EXPECT_LT(d.rows[stage].first, bound[stage]) << r.out;
        EXPECT_GT(bound[stage], 0);
        std::string file = stage;
        EXPECT_TRUE(fs::exists(Path("db/" + file + ".gpu.exr")));
        EXPECT_TRUE(fs::exists(Path("db/" + file + ".cpu.exr")));
    }
    // Every optional stage, in order, on the whole color. exp's bound as above from the
    // stage before it; cycle spinning averages the shifted runs' exps, whose log error is
    // not printed (only the unshifted run's stages are): taken as at most twice the
    // unshifted one's, so 4 dz^2; keep mean scales by a ratio of sums good to ~1e-7.
    r =
        Run("diff f.exr --method bayes --no-split --colour opponent --spins 2 --keep-mean "
            "--noise auto --bayes-mean-radius 0 --dump db2");
    ASSERT_EQ(r.code, 0) << r.All();
    d = ParseDiff(r.out);
    ASSERT_EQ(d.order,
              (std::vector<std::string>{"log", "opponent", "analysis", "moments", "fits",
                                        "shrinkage", "synthesis", "opponent inverse", "exp",
                                        "cycle spinning", "keep mean"}))
        << r.out;
    maxZ = 0;
    for (float z : io::ReadImage(Path("db2/opponent-inverse.cpu.exr").string()).data)
        maxZ = std::max(maxZ, double(std::fabs(z)));
    dz = d.rows["opponent inverse"].second * maxZ + (3 + 2 * maxZ) * u;
    EXPECT_LT(d.rows["exp"].first, dz * dz * 1.01) << r.out;
    for (const char *stage : {"cycle spinning", "keep mean"})
        EXPECT_LT(d.rows[stage].first, 4 * dz * dz) << stage << "\n" << r.out;
    for (const char *stage : {"log", "opponent", "analysis", "moments"})
        EXPECT_LT(d.rows[stage].first, 1e-11) << stage << "\n" << r.out;
    EXPECT_LT(d.rows["fits"].first, 1e-9) << r.out;
    // A 1x1 frame has no detail band: log and exp only.
    ASSERT_EQ(Run("render --size 1x1 --spp 2 -o one.exr").code, 0);
    r = Run("diff one.exr --method bayes --bayes-mean-radius 0");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_EQ(ParseDiff(r.out).order, (std::vector<std::string>{"log", "exp"})) << r.out;
}

TEST_F(CliTest, RenderAndCompare) {
    RunResult r =
        Run("render --scene cornell --size 12x8 --spp 2 --layers all -o f.exr "
            "--preview f.png");
    ASSERT_EQ(r.code, 0) << r.All();
    r = Run("info f.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    for (const char *layer :
         {"color", "variance", "spp", "min", "max", "hist", "direct", "indirect", "pivot",
          "albedo", "normal", "depth", "objectId", "partId"})
        EXPECT_TRUE(Contains(r.out, layer)) << layer;
    EXPECT_TRUE(Contains(r.out, "mcd:scene = cornell"));
    r = Run("render --size 12x8 --spp 1 --seed 9 -o g.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    r = Run("compare f.exr f.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "PSNR inf"));
    r = Run("compare g.exr f.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "relMSE"));
    EXPECT_TRUE(
        IsError(Run("render --scene nope -o h.exr"), ErrorKind::InvalidArgument, "cornell"));
    r = Run("render --spp 0 -o h.exr");  // a value out of its range: a usage error
    EXPECT_EQ(r.code, int(tool::ExitStatus::Usage)) << r.All();
    EXPECT_TRUE(Contains(r.err, "--spp: 0 is out of range (at least 1)"));
    EXPECT_TRUE(
        IsError(Run("render --layers hist,nope -o h.exr"), ErrorKind::InvalidArgument, "nope"));
    EXPECT_TRUE(IsError(Run("render --size 4x4 -o h.png"), ErrorKind::InvalidArgument, ".png"));
    EXPECT_FALSE(fs::exists(Path("h.exr")));
    EXPECT_TRUE(IsError(Run("compare f.exr missing.exr"), ErrorKind::Io, "missing.exr"));
}

TEST_F(CliTest, DenoiseAwr) {
    ASSERT_EQ(Run("render --size 24x16 --spp 4 -o n.exr").code, 0);
    ASSERT_EQ(Run("render --size 24x16 --spp 64 --seed 5 -o r.exr").code, 0);
    RunResult r = Run("denoise n.exr --method awr --explain -o d.exr --reference r.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "soft shrinkage"));
    EXPECT_TRUE(Contains(r.out, "PSNR"));
    EXPECT_TRUE(Contains(r.out, "mean brightness "))
        << r.out;  // beside the error, before -> after
    // The plan lists the GPU buffers: awr's own, and nothing for layers it does not use.
    EXPECT_TRUE(Contains(r.out, "GPU buffers:")) << r.out;
    EXPECT_TRUE(Contains(r.out, "awr.color")) << r.out;
    EXPECT_FALSE(Contains(r.out, "hist")) << r.out;
    EXPECT_EQ(io::ReadImage(Path("d.exr").string()).width, 24);
    // --awr-spins: the plan says so, the diff compares the average with the reference's.
    r = Run("denoise n.exr --method awr --awr-spins 2 --explain -o s.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "cycle spinning: the average over 2 x 2 shifts")) << r.out;
    r = Run("diff n.exr --method awr --awr-spins 3 --max-nmse 1e-9");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "  cycle spinning ")) << r.out;
    r = Run("denoise n.exr --method awr --awr-spins 9 -o s.exr");  // refused by CLI11's range
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.All(), "--awr-spins: 9 is out of range (1 to 8)")) << r.All();
    r = Run("denoise n.exr --variance layer --cs 0 --auto-candidates awr --explain -o e.exr");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "cs is 0"));
    EXPECT_TRUE(IsError(Run("denoise n.exr --method nope -o f.exr"), ErrorKind::InvalidArgument,
                        "unknown method 'nope'"));
    // A reference of the wrong size is refused before anything is written over a good file.
    ASSERT_EQ(Run("render --size 12x8 --spp 2 -o small.exr").code, 0);
    std::ofstream(Path("keep.exr")) << "good";
    EXPECT_TRUE(IsError(Run("denoise n.exr -o keep.exr --reference small.exr"),
                        ErrorKind::InvalidArgument, "12x8"));
    std::ifstream kept(Path("keep.exr"));
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(kept)), {}), "good");
    Image color(8, 8, 3, 0.5f);
    io::WriteExr(Path("bare.exr").string(), {{"color", &color}});
    EXPECT_TRUE(IsError(Run("denoise bare.exr --method awr -o f.exr"), ErrorKind::MissingLayer,
                        "variance layer"));
    EXPECT_FALSE(fs::exists(Path("f.exr")));
    // auto (the default) on a colour without statistics (no variance, no halves) runs nfor
    // alone and says what it left out and why; with --auto-plain combine it runs every
    // method the frame has the layers for and estimates the noise from the frame itself.
    r = Run("denoise bare.exr -o g.exr --explain");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "auto: nfor alone")) << r.out;
    EXPECT_TRUE(Contains(r.out, "left out awr: no variance layer")) << r.out;
    EXPECT_TRUE(Contains(r.out, "left out rhf: no histogram")) << r.out;
    r = Run("denoise bare.exr -o g.exr --explain --auto-plain combine");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "auto: ran bayes")) << r.out;
    EXPECT_TRUE(Contains(r.out, "the frame's own noise estimate")) << r.out;
    // With a variance layer each candidate's error is estimated (SURE), and the map of the
    // largest weights is written on request.
    r = Run("denoise n.exr -o g.exr --explain --auto-map map.png");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "left out awr: it runs where --auto-candidates names it"))
        << r.out;
    EXPECT_TRUE(Contains(r.out, "auto: ran bayes")) << r.out;
    EXPECT_TRUE(Contains(r.out, "SURE on the variance layer")) << r.out;
    EXPECT_TRUE(fs::exists(Path("map.png")));
    // A refused frame (NaN color) leaves the good file at the output path alone.
    io::Frame noisy = io::ReadFrame(Path("n.exr").string());
    noisy.layers["color"].At(0, 3, 4) = NAN;
    std::vector<std::pair<std::string, const Image *>> layers;
    for (const auto &[name, image] : noisy.layers) layers.push_back({name, &image});
    io::WriteExr(Path("nan.exr").string(), layers);
    EXPECT_TRUE(
        IsError(Run("denoise nan.exr -o keep.exr"), ErrorKind::NonFiniteInput, "pixel (4, 3)"));
    std::ifstream keptAgain(Path("keep.exr"));
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(keptAgain)), {}), "good");
}

// References are rendered once and then come from the cache (XDG_CACHE_HOME).
TEST_F(CliTest, ReferenceIsCached) {
    std::string cache = "XDG_CACHE_HOME=" + Path("cache").string() + " ";
    RunResult r = Run("render --reference --spp 8 --size 10x6 -o a.exr", cache);
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_FALSE(Contains(r.out, "from the cache"));
    r = Run("render --reference --spp 8 --size 10x6 -o b.exr", cache);
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "from the cache"));
    io::Frame a = io::ReadFrame(Path("a.exr").string()),
              b = io::ReadFrame(Path("b.exr").string());
    ASSERT_EQ(a.layers.size(), b.layers.size());
    for (const auto &[name, image] : a.layers)
        EXPECT_TRUE(BitIdentical(image, b.Get(name))) << name;
}

// The error-against-time report: one row per (scene, spp, method) whose figures agree with
// a direct measurement, a plot, crops, and refusals of bad ladders before any work.
TEST_F(CliTest, BenchQuality) {
    std::string cache = "XDG_CACHE_HOME=" + Path("cache").string() + " ";
    RunResult r =
        Run("bench quality --scenes dof-arealight --size 24x16 --spp 2,8 --reference-spp 64 "
            "--crop-spp 8 --methods awr -o bq",
            cache);
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "| dof-arealight | awr |"));
    std::ifstream csv(Path("bq/quality.csv"));
    std::vector<std::string> lines;
    for (std::string line; std::getline(csv, line);) lines.push_back(line);
    ASSERT_GE(lines.size(), 1u + 2 * 2) << "header + (mc, awr, ...) x 2 spp";
    EXPECT_EQ(lines[0].rfind("scene,spp,method,", 0), 0u);
    for (const char *method : {",mc,", ",awr,"})
        EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                                [&](const std::string &l) { return Contains(l, method); }),
                  2)
            << method;
    // The MC row at 2 spp is the plain render: its relMSE is what compare measures.
    ASSERT_EQ(Run("render --scene dof-arealight --size 24x16 --spp 2 -o mc2.exr").code, 0);
    ASSERT_EQ(
        Run("render --scene dof-arealight --size 24x16 --spp 64 --reference -o ref.exr", cache)
            .code,
        0);
    io::Frame mc = io::ReadFrame(Path("mc2.exr").string()),
              ref = io::ReadFrame(Path("ref.exr").string());
    ErrorMetrics error = CompareImages(mc.Get("color"), ref.Get("color"));
    double relMse = error.relMse;
    std::string row = *std::find_if(lines.begin(), lines.end(), [](const std::string &l) {
        return l.rfind("dof-arealight,2,mc,", 0) == 0;
    });
    std::vector<std::string> fields;
    std::stringstream stream(row);
    for (std::string f; std::getline(stream, f, ',');) fields.push_back(f);
    ASSERT_EQ(fields.size(), 13u) << row;
    EXPECT_NEAR(std::stod(fields[7]), relMse, 1e-5 * relMse) << row;
    EXPECT_TRUE(Contains(lines[0], ",brightness,darkest_object,darkest_object_id"));
    EXPECT_NEAR(std::stod(fields[10]), error.brightness, 1e-5) << row;
    // The darkest object: luminance summed over an id of the frame with every layer (the
    // same render), over the reference's, of the objects of 64 pixels or more.
    ASSERT_EQ(
        Run("render --scene dof-arealight --size 24x16 --spp 2 --layers all -o full2.exr").code,
        0);
    const Image &ids = io::ReadFrame(Path("full2.exr").string()).Get("objectId");
    std::map<int, std::array<double, 3>> sums;  // pixels, mc's light, the reference's
    auto luminance = [](const Image &image, int y, int x) {
        return 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) +
               0.0722 * image.At(2, y, x);
    };
    for (int y = 0; y < ids.height; ++y)
        for (int x = 0; x < ids.width; ++x) {
            auto &s = sums[int(std::lround(ids.At(0, y, x)))];
            s[0] += 1, s[1] += luminance(mc.Get("color"), y, x),
                s[2] += luminance(ref.Get("color"), y, x);
        }
    double darkest = INFINITY;
    int darkestId = -1;
    for (const auto &[id, s] : sums)
        if (s[0] >= 64 && s[2] > 0 && s[1] / s[2] < darkest)
            darkest = s[1] / s[2], darkestId = id;
    ASSERT_GE(darkestId, 0) << "no object of 64 pixels";
    EXPECT_NEAR(std::stod(fields[11]), darkest, 1e-4) << row;
    EXPECT_EQ(fields[12], std::to_string(darkestId)) << row;
    for (const char *file :
         {"bq/index.html", "bq/dof-arealight.svg", "bq/dof-arealight-input.png",
          "bq/dof-arealight-awr.png", "bq/dof-arealight-reference.png"})
        EXPECT_TRUE(fs::exists(Path(file))) << file;
    EXPECT_TRUE(
        IsError(Run("bench quality --spp 0 -o bq2"), ErrorKind::InvalidArgument, "--spp"));
    EXPECT_TRUE(
        IsError(Run("bench quality --scenes nope -o bq2"), ErrorKind::InvalidArgument, "nope"));
    EXPECT_TRUE(IsError(Run("bench quality --methods awr,nope -o bq2"),
                        ErrorKind::InvalidArgument, "'nope'"));
    EXPECT_FALSE(fs::exists(Path("bq2")));
}

TEST_F(CliTest, BenchWavelet) {
    RunResult r = Run("bench wavelet --size 64x64 --levels 2 --repeat 1 --no-pywt");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(Contains(r.out, "GPU time"));
    const std::string key = "round-trip max |error| ";
    size_t at = r.out.find(key);
    ASSERT_NE(at, std::string::npos) << r.out;
    double error = std::strtod(r.out.c_str() + at + key.size(), nullptr);
    EXPECT_LT(error, 1e-5) << r.out;
    EXPECT_EQ(r.out.find("PyWavelets"), std::string::npos) << "--no-pywt ignored";

    r = Run("bench wavelet --size 0x5");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "0x5"));
    r = Run("bench wavelet --size 64x64 --basis db4");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "db4"));
    r = Run("bench wavelet --size 8x8 --levels 4");
    EXPECT_TRUE(IsError(r, ErrorKind::InvalidArgument, "--levels 4"));
}

}  // namespace
}  // namespace mcd::test
