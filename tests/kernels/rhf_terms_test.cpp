// Kernel rhf/terms (RecordRhfTerms) alone against the reference's pixel-pair terms
// (ref::RhfPixelPairTerms): random histograms with empty pixels, fractional and integer
// bins, saturated fireflies that trip the bright veto, one or six histogram buffers, whole
// frames and strips of rows, odd sizes down to 1x1. Its bin maxima input comes from the
// reference (ref::RhfBlockMax). Histograms are finite and >= 0 by contract (no NaN cases).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/rhf.h"
#include "cpu_reference/rhf_steps.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/kernels/rhf_blockmax.h"
#include "host/kernels/rhf_terms.h"
#include "host/vk/buffer.h"
#include "host/vk/recorder.h"
#include "rhf/terms.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

enum class Bins { Integer, Fractional, Constant };

struct TermsCase {
    int w, h, perColour, b;
    Bins bins;
    int perSlot;  // planes per histogram buffer, 0: all in one
    float histScale, brightVeto;
    int rowBase, rows;  // the strip; rows 0: the whole frame

    std::string Name() const {
        const char *kind = bins == Bins::Integer      ? "integer"
                           : bins == Bins::Fractional ? "fractional"
                                                      : "constant";
        return fmt::format("{}x{}_n{}_b{}_{}_slot{}_scale{}_veto{}_rows{}to{}", w, h, perColour,
                           b, kind, perSlot, int(histScale * 100), int(brightVeto * 100),
                           rowBase, rowBase + Rows());
    }
    int Rows() const { return rows > 0 ? rows : h; }
};

// Counts 0 (one pixel in ten) to 24; bins zero two times in five, else integer 1..4 or
// U[0, 3); the saturated bins (last two of a colour) mostly empty, with fireflies of 4..12
// on one pixel in twenty.
Image RandomHistogram(const TermsCase &c, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    const int bins = 3 * c.perColour;
    Image hist(c.w, c.h, bins + 1);
    for (int y = 0; y < c.h; ++y)
        for (int x = 0; x < c.w; ++x) {
            bool firefly = unit(rng) < 0.05f;
            for (int i = 0; i < bins; ++i) {
                bool saturated = i % c.perColour >= c.perColour - 2;
                float v = c.bins == Bins::Integer ? float(1 + rng() % 4) : 3.f * unit(rng);
                if (saturated)
                    v = firefly ? 4.f + float(rng() % 9) : (unit(rng) < 0.1f ? v : 0.f);
                hist.At(i, y, x) = unit(rng) < 0.4f && !firefly ? 0.f : v;
            }
            hist.At(bins, y, x) = unit(rng) < 0.1f ? 0.f : float(1 + rng() % 24);
        }
    // Constant: every pixel the first one's histogram, with samples.
    if (c.bins == Bins::Constant) {
        hist.At(bins, 0, 0) = 8.f;
        for (int i = 0; i <= bins; ++i)
            std::fill_n(hist.Plane(i), hist.PixelCount(), hist.At(i, 0, 0));
    }
    return hist;
}

RhfHistogram Upload(vk::Context &ctx, const Image &hist, int perSlot) {
    RhfHistogram gpu;
    gpu.width = hist.width;
    gpu.height = hist.height;
    gpu.planes = hist.channels;
    gpu.planesPerSlot = perSlot > 0 ? perSlot : hist.channels;
    for (int first = 0; first < hist.channels; first += gpu.planesPerSlot) {
        size_t bytes = size_t(std::min(gpu.planesPerSlot, hist.channels - first)) *
                       hist.PixelCount() * sizeof(float);
        gpu.slots.emplace_back(ctx, bytes, "hist").Upload(hist.Plane(first), bytes);
    }
    return gpu;
}

struct Terms {
    std::vector<float> sum, count;
};

class RhfTermsKernel : public GpuTestWithParam<TermsCase> {
  protected:
    Terms Run(const RhfHistogram &hist, const std::vector<float> &blockMax) {
        const TermsCase &c = GetParam();
        size_t size = size_t(c.b + 1) * (2 * c.b + 1) * c.Rows() * c.w;
        vk::Buffer maxima(Ctx(), blockMax.size() * sizeof(float), "blockMax"),
            sum(Ctx(), size * sizeof(float), "termSum"),
            count(Ctx(), size * sizeof(float), "termCount");
        maxima.UploadFloats(blockMax);
        vk::Recorder recorder(Ctx());
        RecordRhfTerms(Ctx(), recorder, hist, c.b, c.rowBase, c.Rows(), c.histScale,
                       c.brightVeto, maxima, sum, count);
        recorder.Submit();
        return {sum.DownloadFloats(size), count.DownloadFloats(size)};
    }
};

// The sum: each term's d = n_q h_p - n_p h_q cancels, so its float error is u times
// 2 |d| (n_q h_p + n_p h_q + |d|) / den, plus about 5 u of the term for the square, the
// three-factor denominator and the division; adding at most 3n positive terms adds 3n u of
// their sum. Both are within (3n + 8) u of the reference's magnitude twin. Counts are
// integers (exact). The veto compares two float sums: a pair whose sides lie within that
// error of each other may go either way and is accepted both ways. The bin test
// h_p + h_q > 1 could differ only on a sum within an ulp above 1, which these inputs do not
// hit.
TEST_P(RhfTermsKernel, MatchesReference) {
    const TermsCase &c = GetParam();
    Image hist = RandomHistogram(c, SeedFromName(c.Name()));
    Image scaled = hist;
    for (float &v : scaled.data) v *= c.histScale;
    Image maxima = ref::RhfBlockMax(hist, c.histScale, RHF_TERMS_PIXELS_PER_LANE);
    RhfHistogram gpuHist = Upload(Ctx(), hist, c.perSlot);
    Terms got = Run(gpuHist, maxima.data);
    const int side = 2 * c.b + 1;
    const double relTol = (3 * c.perColour + 8) * kUnitRoundoff;
    int vetoed = 0, counted = 0, ambiguous = 0, reported = 0;
    for (int dy = 0; dy <= c.b; ++dy)
        for (int dx = -c.b; dx <= c.b; ++dx)
            for (int r = 0; r < c.Rows(); ++r)
                for (int x = 0; x < c.w; ++x) {
                    int y = c.rowBase + r, qx = x + dx, qy = y + dy;
                    size_t at = ((size_t(dy) * side + dx + c.b) * c.Rows() + r) * c.w + x;
                    ref::RhfPairTerms e;
                    if (qx >= 0 && qx < c.w && qy < c.h)
                        e = ref::RhfPixelPairTerms(scaled, x, y, qx, qy, c.brightVeto);
                    double err = std::fabs(got.sum[at] - e.sum);
                    bool near = c.brightVeto > 0 && std::fabs(e.saturated - e.vetoBound) <=
                                                        relTol * (e.magnitude + e.vetoBound);
                    float gpuCount = got.count[at];
                    bool countOk = gpuCount == (e.vetoed ? -1.f : float(e.counted)) ||
                                   (near && e.saturated > 0 &&
                                    (gpuCount == -1.f || gpuCount == float(e.counted)));
                    ambiguous += near && e.saturated > 0;
                    vetoed += e.vetoed;
                    counted += e.counted > 0;
                    if ((err > relTol * e.magnitude || !countOk) && reported++ < 8)
                        ADD_FAILURE() << fmt::format(
                            "pixel ({}, {}) offset ({}, {}): sum {:.9g} count {} expected "
                            "{:.9g} count {}{} (magnitude {:.3g})",
                            x, y, dx, dy, got.sum[at], gpuCount, e.sum, e.counted,
                            e.vetoed ? " vetoed" : "", e.magnitude);
                }
    EXPECT_EQ(reported, 0) << "pairs differ";
    if (c.w * c.h > 1) {
        EXPECT_GT(counted, 0);
    }
    if (c.brightVeto > 0 && c.bins != Bins::Constant && c.w * c.h > 20) {
        EXPECT_GT(vetoed, 0) << "no pair was vetoed";
    }
    std::printf("[ terms ] %d counted pairs, %d vetoed, %d near the veto's bound\n", counted,
                vetoed, ambiguous);
    // Reruns are bit-identical, and so is a run without the bin maxima's shortcut (every
    // block's maximum FLT_MAX): the bins it leaves out count nothing.
    Terms again = Run(gpuHist, maxima.data);
    std::vector<float> open(maxima.data.size(), FLT_MAX);
    Terms all = Run(gpuHist, open);
    for (const Terms *other : {&again, &all}) {
        EXPECT_EQ(std::memcmp(got.sum.data(), other->sum.data(), got.sum.size() * 4), 0);
        EXPECT_EQ(std::memcmp(got.count.data(), other->count.data(), got.count.size() * 4), 0);
    }
}

std::vector<TermsCase> Cases() {
    return {
        {1, 1, 1, 1, Bins::Integer, 0, 1.f, 0.3f, 0, 0},
        {9, 1, 5, 2, Bins::Fractional, 0, 1.f, 0.3f, 0, 0},
        {1, 7, 5, 2, Bins::Integer, 0, 1.f, 0.f, 0, 0},
        {23, 11, 20, 3, Bins::Integer, 0, 1.f, 0.3f, 0, 0},
        {23, 11, 20, 3, Bins::Fractional, 11, 0.37f, 0.3f, 3, 5},
        {37, 13, 10, 6, Bins::Fractional, 0, 1.f, 0.f, 0, 0},
        {17, 9, 2, 2, Bins::Integer, 3, 2.5f, 0.5f, 2, 6},
        {19, 8, 6, 2, Bins::Constant, 0, 1.f, 0.3f, 0, 0},
    };
}

INSTANTIATE_TEST_SUITE_P(Cases, RhfTermsKernel, testing::ValuesIn(Cases()),
                         [](const testing::TestParamInfo<TermsCase> &info) {
                             return info.param.Name();
                         });

}  // namespace
}  // namespace mcd::test
