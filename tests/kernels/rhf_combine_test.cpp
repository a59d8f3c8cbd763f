// Kernel rhf/combine (RecordRhfCombine) alone against the reference's recombination
// (ref::RhfCombine: filtered - U(low) + U(coarse), U bicubic): whole frames of odd and
// even sizes down to 1x1, colours uniform, with fireflies, constant and laced with
// NaN/Inf, and a tile's window inside a larger frame (compared where its taps stay inside
// the window, as tiles keep only those pixels).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cpu_reference/rhf.h"
#include "cpu_reference/rhf_steps.h"
#include "harness/compare.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/rhf_combine.h"
#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

struct CombineCase {
    int w, h;  // the frame
    InputKind kind;
    int tileX = 0, tileY = 0, tileW = 0, tileH = 0;  // tileW 0: the whole frame

    bool Tiled() const { return tileW > 0; }
    std::string Name() const {
        std::string tile =
            Tiled() ? fmt::format("_tile{}x{}at{}_{}", tileW, tileH, tileX, tileY) : "";
        return fmt::format("{}x{}_{}{}", w, h, InputKindName(kind), tile);
    }
};

// Per pixel and channel |filtered| + 1.5625 (largest |low| + largest |coarse| over the 4x4
// coarse pixels its taps read): Keys' absolute weights sum to at most 1.25 per axis.
Image Magnitude(const Image &filtered, const Image &low, const Image &coarse) {
    auto taps = [](int x, int n, int out) {
        int i0 = int(std::floor((x + 0.5) * n / out - 0.5));
        std::vector<int> at;
        for (int k = -1; k <= 2; ++k) at.push_back(ref::RhfMirror(i0 + k, n));
        return at;
    };
    Image m(filtered.width, filtered.height, filtered.channels);
    for (int c = 0; c < m.channels; ++c)
        for (int y = 0; y < m.height; ++y)
            for (int x = 0; x < m.width; ++x) {
                double largest[2] = {0, 0};
                for (int j : taps(y, low.height, m.height))
                    for (int i : taps(x, low.width, m.width)) {
                        largest[0] = std::max(largest[0], double(std::fabs(low.At(c, j, i))));
                        largest[1] =
                            std::max(largest[1], double(std::fabs(coarse.At(c, j, i))));
                    }
                m.At(c, y, x) =
                    float(std::fabs(filtered.At(c, y, x)) + 1.5625 * (largest[0] + largest[1]));
            }
    return m;
}

class RhfCombineKernel : public GpuTestWithParam<CombineCase> {};

// The kernel finds each tap's weight from the pixel's coarse position t (three float
// operations on values up to the coarse extent T: within 3 T u) through Keys' cubic (slope
// at most 1.5, a few operations on values below 8): each 1D weight within (4.5 T + 8) u,
// each 2D weight within (9 T + 17) u; over 16 taps of both images that is 16 (9 T + 17) u
// times their largest magnitude, plus 16 u of the sums and 2 u of the final sum and
// difference: within (92 T + 192) u of the magnitude above.
TEST_P(RhfCombineKernel, MatchesReference) {
    const CombineCase &c = GetParam();
    uint64_t seed = SeedFromName(c.Name());
    const int cw = (c.w + 1) / 2, ch = (c.h + 1) / 2;
    Image filtered = MakeInput(c.kind, c.w, c.h, 3, seed);
    Image low = MakeInput(c.kind, cw, ch, 3, seed + 1);
    Image coarse = MakeInput(c.kind, cw, ch, 3, seed + 2);
    Image expected = ref::RhfCombine(filtered, low, coarse);
    Image magnitude = Magnitude(filtered, low, coarse);
    // The window the kernel sees: the whole frame or a tile with its coarse crops.
    int x0 = c.tileX, y0 = c.tileY, w = c.Tiled() ? c.tileW : c.w,
        h = c.Tiled() ? c.tileH : c.h;
    int cx0 = x0 / 2, cy0 = y0 / 2, wc = (w + 1) / 2, hc = (h + 1) / 2;
    vk::GpuImage f(Ctx(), w, h, 3, "filtered"), l(Ctx(), wc, hc, 3, "low"),
        k(Ctx(), wc, hc, 3, "coarse"), out(Ctx(), w, h, 3, "out");
    f.Upload(filtered.Crop(x0, y0, x0 + w, y0 + h));
    l.Upload(low.Crop(cx0, cy0, cx0 + wc, cy0 + hc));
    k.Upload(coarse.Crop(cx0, cy0, cx0 + wc, cy0 + hc));
    RhfCombineWindow window;
    if (c.Tiled()) window = {x0, y0, c.w, c.h};
    auto run = [&] {
        vk::Recorder recorder(Ctx());
        RecordRhfCombine(Ctx(), recorder, f, l, k, out, window);
        recorder.Submit();
        return out.Download();
    };
    Image got = run();
    // A tile's outer pixels read coarse pixels outside its crop: compare 4 pixels in.
    int m = c.Tiled() ? 4 : 0;
    Image want = expected.Crop(x0 + m, y0 + m, x0 + w - m, y0 + h - m);
    double T = std::max(cw, ch);
    Tolerance tol{(92 * T + 192) * kUnitRoundoff, 0, 1e-10};
    EXPECT_TRUE(ImagesMatch(want, got.Crop(m, m, w - m, h - m),
                            magnitude.Crop(x0 + m, y0 + m, x0 + w - m, y0 + h - m), tol));
    EXPECT_TRUE(BitIdentical(got, run()));
}

std::vector<CombineCase> Cases() {
    return {{1, 1, InputKind::Uniform},
            {2, 1, InputKind::Uniform},
            {1, 5, InputKind::LogNormalFireflies},
            {7, 6, InputKind::Uniform},
            {37, 29, InputKind::Uniform},
            {37, 29, InputKind::LogNormalFireflies},
            {37, 29, InputKind::Constant},
            {37, 29, InputKind::NonFinite},
            {64, 33, InputKind::Impulse},
            {40, 30, InputKind::Uniform, 8, 6, 20, 14},
            {41, 31, InputKind::LogNormalFireflies, 20, 10, 21, 21}};
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfCombineKernel, testing::ValuesIn(Cases()),
                         [](const testing::TestParamInfo<CombineCase> &info) {
                             return info.param.Name();
                         });

}  // namespace
}  // namespace mcd::test
