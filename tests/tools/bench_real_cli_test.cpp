// `mcdenoise bench real` (issue #29) on a synthetic set whose figures are known: the input
// rows' relMSE, brightness ratio and worst 1% as computed here from their definitions, the
// reference's own noise from its halves, a method refused with its reason, the report's
// files; and the errors for a set that is not one. Never runs the peer (--no-oidn).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "harness/tool.h"
#include "host/image.h"
#include "host/io/frame.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

constexpr int kSide = 16;

Image Random(std::mt19937 &rng, float lo, float hi) {
    std::uniform_real_distribution<float> u(lo, hi);
    Image image(kSide, kSide, 3);
    for (float &v : image.data) v = u(rng);
    return image;
}

// One CSV row of real.csv by its scene, frame and method: the fields by column name.
std::map<std::string, std::string> CsvRow(const std::string &csv, const std::string &key) {
    std::istringstream stream(csv);
    std::string header, line;
    std::getline(stream, header);
    std::vector<std::string> names;
    std::stringstream h(header);
    for (std::string name; std::getline(h, name, ',');) names.push_back(name);
    while (std::getline(stream, line)) {
        if (line.rfind(key + ",", 0) != 0) continue;
        std::map<std::string, std::string> row;
        std::vector<std::string> fields;
        std::string field;
        bool quoted = false;
        for (char c : line) {
            if (c == '"')
                quoted = !quoted;
            else if (c == ',' && !quoted)
                fields.push_back(field), field.clear();
            else
                field += c;
        }
        fields.push_back(field);
        for (size_t i = 0; i < names.size() && i < fields.size(); ++i)
            row[names[i]] = fields[i];
        return row;
    }
    return {};
}

// Each pixel's relMSE term (mean over the channels), from the definition.
std::vector<double> Terms(const Image &x, const Image &r) {
    std::vector<double> terms;
    for (int y = 0; y < kSide; ++y)
        for (int px = 0; px < kSide; ++px) {
            double sum = 0;
            for (int c = 0; c < 3; ++c) {
                double d = double(x.At(c, y, px)) - r.At(c, y, px);
                sum += d * d / (double(r.At(c, y, px)) * r.At(c, y, px) + 0.01);
            }
            terms.push_back(sum / 3);
        }
    return terms;
}

double Luminance(const Image &image) {
    double sum = 0;
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x)
            sum += 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) +
                   0.0722 * image.At(2, y, x);
    return sum;
}

void ExpectRelative(const std::string &got, double want, double tolerance,
                    const std::string &what) {
    ASSERT_FALSE(got.empty()) << what;
    EXPECT_LE(std::abs(std::stod(got) - want), tolerance * std::abs(want))
        << what << ": " << got << " for " << want;
}

class CliBenchReal : public ::testing::Test {
  protected:
    // A set with one scene: a reference with halves a = r + d, b = r - d; a plain frame
    // of color only, 0.9 x the reference but for three bad pixels; an accumulated frame
    // with statistics, equal to the reference.
    void SetUp() override {
        std::mt19937 rng(29);
        fs::create_directories(tool.Path("set/scene_a"));
        reference = Random(rng, 0.05f, 1.f);
        Image delta = Random(rng, -0.02f, 0.02f), half0 = reference, half1 = reference;
        for (size_t i = 0; i < reference.Size(); ++i)
            half0.data[i] += delta.data[i], half1.data[i] -= delta.data[i];
        // The mean of the halves as float, as the reference is stored.
        for (size_t i = 0; i < reference.Size(); ++i)
            reference.data[i] = 0.5f * (half0.data[i] + half1.data[i]);
        for (size_t i = 0; i < reference.Size(); ++i) {
            double a = half0.data[i], b = half1.data[i], r = reference.data[i];
            noise += (a - b) * (a - b) / 4 / (r * r + 0.01) / double(reference.Size());
        }
        io::WriteExr(Path("set/scene_a/ref.exr"),
                     {{"color", &reference}, {"half0.color", &half0}, {"half1.color", &half1}},
                     {{"mcd:spp", "4096"}});
        plain = reference;
        for (float &v : plain.data) v *= 0.9f;
        for (int k = 0; k < 3; ++k) plain.At(1, 5, 3 + 4 * k) += 3.f + k;
        io::WriteExr(Path("set/scene_a/plain.exr"), {{"color", &plain}});
        Image variance(kSide, kSide, 3, 1e-3f), spp(kSide, kSide, 1, 16.f);
        io::WriteExr(Path("set/scene_a/acc.exr"),
                     {{"color", &reference}, {"variance", &variance}, {"spp", &spp}},
                     {{"mcd:spp", "16"}});
    }
    std::string Path(const std::string &name) const { return tool.Path(name).string(); }
    std::string Read(const std::string &name) const {
        std::ifstream in(tool.Path(name));
        return {std::istreambuf_iterator<char>(in), {}};
    }

    ToolDir tool{"mcd_bench_real_cli"};
    Image reference, plain;
    double noise = 0;
};

TEST_F(CliBenchReal, InputRowsAndReferenceNoiseFollowTheirDefinitions) {
    ToolResult r = tool.Run("bench real set --no-oidn --methods awr -o report");
    ASSERT_EQ(r.code, 0) << r.All();
    std::string csv = Read("report/real.csv");

    std::vector<double> terms = Terms(plain, reference);
    double relMse = 0;
    for (double t : terms) relMse += t / double(terms.size());
    // 256 pixels: the worst 1% is the 3 worst, here the three bad ones.
    std::sort(terms.begin(), terms.end(), std::greater<>());
    double worst = (terms[0] + terms[1] + terms[2]) / 3;
    auto input = CsvRow(csv, "scene_a,plain,input");
    ExpectRelative(input["relmse"], relMse, 1e-5, "plain input relMSE");
    ExpectRelative(input["worst1pct"], worst, 1e-5, "plain input worst 1%");
    ExpectRelative(input["brightness"], Luminance(plain) / Luminance(reference), 1e-4,
                   "plain input brightness");

    auto accumulated = CsvRow(csv, "scene_a,accumulated,input");
    EXPECT_EQ(std::stod(accumulated["relmse"]), 0.0);
    EXPECT_EQ(std::stod(accumulated["brightness"]), 1.0);

    // awr needs statistics: refused on the plain frame with the reason, run on the other.
    auto refused = CsvRow(csv, "scene_a,plain,awr");
    EXPECT_TRUE(refused["relmse"].empty());
    EXPECT_NE(refused["refused"].find("variance"), std::string::npos) << refused["refused"];
    auto ran = CsvRow(csv, "scene_a,accumulated,awr");
    EXPECT_TRUE(ran["refused"].empty()) << ran["refused"];
    EXPECT_TRUE(std::isfinite(std::stod(ran["relmse"])));

    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, std::regex("its own relMSE noise ([0-9.e+-]+)")))
        << r.out;
    ExpectRelative(m[1], noise, 5e-3, "reference noise (printed to 3 digits)");

    // Every image the page shows exists, and so do the strips.
    std::string html = Read("report/index.html");
    std::regex source("src='([^']+)'");
    int images = 0;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), source);
         it != std::sregex_iterator(); ++it, ++images)
        EXPECT_TRUE(fs::exists(tool.Path("report/" + (*it)[1].str()))) << (*it)[1];
    EXPECT_EQ(images, 5);  // plain: input, reference; accumulated: input, awr, reference
    EXPECT_TRUE(fs::exists(tool.Path("report/scene_a-plain.png")));
    EXPECT_TRUE(fs::exists(tool.Path("report/scene_a-accumulated.png")));
    EXPECT_NE(Read("report/real.md").find("| mean over the scenes |"), std::string::npos);
}

// Each object's light from the accumulated frame's objectId layer, for both frames' rows:
// an object of its ids' pixels, one under kObjectPixels left out; the darkest named in the
// CSV, the rows and the object table.
TEST_F(CliBenchReal, ObjectsLightFollowsItsDefinition) {
    // Object 1 the left half (128 pixels), 2 the right half but 8 pixels of 3.
    Image ids(kSide, kSide, 1), variance(kSide, kSide, 3, 1e-3f), spp(kSide, kSide, 1, 16.f);
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x)
            ids.At(0, y, x) = x < kSide / 2 ? 1.f : y == 0 && x >= kSide / 2 ? 3.f : 2.f;
    io::WriteExr(
        Path("set/scene_a/acc.exr"),
        {{"color", &reference}, {"variance", &variance}, {"spp", &spp}, {"objectId", &ids}},
        {{"mcd:spp", "16"}});
    ToolResult r = tool.Run("bench real set --no-oidn --methods awr -o report");
    ASSERT_EQ(r.code, 0) << r.All();

    // The plain frame's light over the reference's per object, from the definition.
    auto light = [&](const Image &image, float id) {
        double sum = 0;
        for (int y = 0; y < kSide; ++y)
            for (int x = 0; x < kSide; ++x)
                if (ids.At(0, y, x) == id)
                    sum += 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) +
                           0.0722 * image.At(2, y, x);
        return sum;
    };
    double one = light(plain, 1) / light(reference, 1),
           two = light(plain, 2) / light(reference, 2);
    // Both lie near 0.9; the bad pixels (x = 3, 7: object 1; x = 11: object 2) lift them.
    ASSERT_NE(one, two);
    std::string csv = Read("report/real.csv");
    auto input = CsvRow(csv, "scene_a,plain,input");
    ExpectRelative(input["darkest_object"], std::min(one, two), 1e-4, "darkest object");
    EXPECT_EQ(input["darkest_object_id"], one < two ? "1" : "2");
    auto accumulated = CsvRow(csv, "scene_a,accumulated,input");
    EXPECT_EQ(std::stod(accumulated["darkest_object"]), 1.0);

    std::string md = Read("report/real.md");
    EXPECT_NE(md.find("| scene_a plain | pixels | input | awr |"), std::string::npos) << md;
    EXPECT_NE(md.find(fmt::format("| object 1 | 128 | {:.3f} |", one)), std::string::npos);
    EXPECT_NE(md.find(fmt::format("| object 2 | 120 | {:.3f} |", two)), std::string::npos);
    EXPECT_EQ(md.find("| object 3 |"), std::string::npos) << "8 pixels are measured";
}

// A transparent film's background: id 0 on the right half, empty (alpha 0) but for a
// column of rims, is no object; id 1, covered, is measured. With alpha 1 everywhere id 0
// is an object like any other.
TEST_F(CliBenchReal, TransparentBackgroundIsNoObject) {
    Image ids(kSide, kSide, 1), alpha(kSide, kSide, 1, 1.f), variance(kSide, kSide, 3, 1e-3f),
        spp(kSide, kSide, 1, 16.f);
    for (int y = 0; y < kSide; ++y)
        for (int x = kSide / 2; x < kSide; ++x) {
            ids.At(0, y, x) = 0.f;
            alpha.At(0, y, x) = x == kSide / 2 ? 0.5f : 0.f;
        }
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide / 2; ++x) ids.At(0, y, x) = 1.f;
    auto run = [&](const Image &coverage) {
        io::WriteExr(Path("set/scene_a/acc.exr"),
                     {{"color", &reference},
                      {"variance", &variance},
                      {"spp", &spp},
                      {"objectId", &ids},
                      {"alpha", &coverage}},
                     {{"mcd:spp", "16"}});
        ToolResult r = tool.Run("bench real set --no-oidn --methods awr -o report");
        EXPECT_EQ(r.code, 0) << r.All();
        return Read("report/real.md");
    };
    std::string md = run(alpha);
    EXPECT_NE(md.find("| object 1 | 128 |"), std::string::npos) << md;
    EXPECT_EQ(md.find("| object 0 |"), std::string::npos) << md;
    EXPECT_EQ(CsvRow(Read("report/real.csv"), "scene_a,plain,input")["darkest_object_id"], "1");

    md = run(Image(kSide, kSide, 1, 1.f));
    EXPECT_NE(md.find("| object 0 | 128 |"), std::string::npos) << md;
}

// Without ids no object is measured and the report has no object table.
TEST_F(CliBenchReal, NoObjectsWithoutIds) {
    ToolResult r = tool.Run("bench real set --no-oidn --methods awr -o report");
    ASSERT_EQ(r.code, 0) << r.All();
    EXPECT_TRUE(
        CsvRow(Read("report/real.csv"), "scene_a,plain,input")["darkest_object"].empty());
    EXPECT_EQ(Read("report/real.md").find("## Objects"), std::string::npos);
}

// A scene with reference chunks (realset.sh while it renders): the reference is the mean
// of the chunks present, whatever an older ref.exr holds, its noise from the odd and the
// even chunks (two halves of 2 and 1 chunks), its spp their sum.
TEST_F(CliBenchReal, ReferenceFromTheChunksPresent) {
    std::mt19937 rng(291);
    fs::create_directories(tool.Path("set/scene_b/ref"));
    Image stale = Random(rng, 0.05f, 1.f);
    io::WriteExr(Path("set/scene_b/ref.exr"), {{"color", &stale}},
                 {{"mcd:spp", "2048"}, {"mcd:accumulatedFrames", "2"}});
    std::vector<Image> chunks;
    Image truth = Random(rng, 0.05f, 1.f);
    for (int k = 0; k < 3; ++k) {
        chunks.push_back(truth);
        Image noise = Random(rng, -0.05f, 0.05f);
        for (size_t i = 0; i < truth.Size(); ++i) chunks[k].data[i] += noise.data[i];
        io::WriteExr(Path(fmt::format("set/scene_b/ref/chunk{:02d}.exr", k + 1)),
                     {{"color", &chunks[k]}}, {{"mcd:spp", "1024"}});
    }
    // A file that is not a chunk: a render in progress.
    io::WriteExr(Path("set/scene_b/ref/chunk04.exr.partial.exr"), {{"color", &stale}});
    fs::last_write_time(
        tool.Path("set/scene_b/ref.exr"),
        fs::last_write_time(tool.Path("set/scene_b/ref/chunk03.exr")) - std::chrono::hours(1));
    Image mean = truth;
    double noise = 0;
    for (size_t i = 0; i < mean.Size(); ++i) {
        double a = (double(chunks[0].data[i]) + chunks[2].data[i]) / 2, b = chunks[1].data[i];
        mean.data[i] =
            float((double(chunks[0].data[i]) + chunks[1].data[i] + chunks[2].data[i]) / 3);
        double r = mean.data[i];
        noise += (a - b) * (a - b) * 2 / 9 / (r * r + 0.01) / double(mean.Size());
    }
    io::WriteExr(Path("set/scene_b/plain.exr"), {{"color", &plain}});

    ToolResult r =
        tool.Run("bench real set --scenes scene_b --no-oidn --methods awr -o report");
    ASSERT_EQ(r.code, 0) << r.All();
    std::vector<double> terms = Terms(plain, mean);
    double relMse = 0;
    for (double t : terms) relMse += t / double(terms.size());
    auto input = CsvRow(Read("report/real.csv"), "scene_b,plain,input");
    ExpectRelative(input["relmse"], relMse, 1e-5,
                   "plain input relMSE against the chunks' mean");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        r.out, m,
        std::regex("reference 3072 spp \\(the mean of 3 chunks in ref/\\), its own relMSE "
                   "noise ([0-9.e+-]+)")))
        << r.out;
    ExpectRelative(m[1], noise, 5e-3, "reference noise from halves of 2 and 1 chunks");
    EXPECT_NE(
        CsvRow(Read("report/real.csv"), "scene_b,accumulated,input")["refused"].find("acc.exr"),
        std::string::npos);

    // Once ref.exr is newer and made from as many chunks, it is the reference.
    io::WriteExr(Path("set/scene_b/ref.exr"), {{"color", &stale}},
                 {{"mcd:spp", "3072"}, {"mcd:accumulatedFrames", "3"}});
    r = tool.Run("bench real set --scenes scene_b --no-oidn --methods awr -o report");
    ASSERT_EQ(r.code, 0) << r.All();
    terms = Terms(plain, stale);
    relMse = 0;
    for (double t : terms) relMse += t / double(terms.size());
    input = CsvRow(Read("report/real.csv"), "scene_b,plain,input");
    ExpectRelative(input["relmse"], relMse, 1e-5, "plain input relMSE against ref.exr");
    EXPECT_NE(r.out.find("its own relMSE noise unknown"), std::string::npos) << r.out;
}

// A peer that fails leaves its rows refused with the last two lines it printed, whole, and
// the run goes on: the methods' rows and the report are written, exit 0.
TEST_F(CliBenchReal, AFailingPeerIsARefusedRowWithItsLastLines) {
    if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "the peer runs by /usr/bin/python3";
    fs::create_directories(tool.Path("peer"));
    std::ofstream(tool.Path("peer/denoise_exr.py"))
        << "import sys\n"
           "print('first line of a long log ' * 20)\n"
           "print(' lib/oidnDenoise.bin: error while loading shared libraries: x.so.2')\n"
           "print('oidnDenoise failed (rc=127)')\n"
           "sys.exit(1)\n";
    ToolResult r = tool.Run("bench real set --oidn peer --methods awr -o report");
    ASSERT_EQ(r.code, 0) << r.All();
    const std::string want =
        "failed: lib/oidnDenoise.bin: error while loading shared "
        "libraries: x.so.2 / oidnDenoise failed (rc=127)";
    std::string csv = Read("report/real.csv");
    for (const char *key : {"scene_a,plain,oidn,", "scene_a,accumulated,oidn color,"}) {
        std::map<std::string, std::string> row = CsvRow(csv, key);
        ASSERT_FALSE(row.empty()) << key << " not in:\n" << csv;
        EXPECT_NE(row["refused"].find(want), std::string::npos)
            << key << ": " << row["refused"];
        EXPECT_EQ(row["refused"].find("first line"), std::string::npos) << row["refused"];
    }
    EXPECT_FALSE(CsvRow(csv, "scene_a,plain,awr,").empty()) << csv;
}

TEST_F(CliBenchReal, RefusesWhatIsNotASet) {
    ToolResult r = tool.Run("bench real missing --no-oidn -o report");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("'missing' is not a directory"), std::string::npos) << r.err;
    r = tool.Run("bench real set --scenes scene_b --no-oidn -o report");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("scene_b"), std::string::npos) << r.err;
    // One chunk is not a reference.
    fs::create_directories(tool.Path("set/scene_b/ref"));
    io::WriteExr(Path("set/scene_b/ref/chunk01.exr"), {{"color", &reference}});
    r = tool.Run("bench real set --scenes scene_b --no-oidn -o report");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("nor two chunks"), std::string::npos) << r.err;
    r = tool.Run("bench real set --oidn nowhere -o report");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("no denoise_exr.py"), std::string::npos) << r.err;
    r = tool.Run("bench real set --methods nosuch --no-oidn -o report");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("unknown method 'nosuch'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mcd::test
