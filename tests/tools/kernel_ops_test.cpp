// The operation formulas of `bench kernels` (tools/mcdenoise/kernel_ops.h) against counts
// made by walking each kernel's loops one operation at a time, on dispatches the real host
// code records (a transform, or a method's run), decoded from their push constants, grid
// and specialization constants as the recorder keeps them. nfor's: kernel_ops_nfor_test.cpp.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <optional>
#include <string>

#include <set>

#include "awr/shrink.h"
#include "bayes/shrink.h"
#include "bayes/swt_shrink.h"
#include "harness/gpu_fixture.h"
#include "host/kernels/awr_shrink.h"
#include "host/vk/gpu_image.h"
#include "host/wavelet.h"
#include "host/wavelet/swt.h"
#include "host/wavelet/transform.h"
#include "pivot/fit.h"
#include "pivot/pivot.h"
#include "rhf/distance.h"
#include "rhf/terms.h"
#include "tests/tools/kernel_ops_walk.h"
#include "tools/mcdenoise/kernel_ops.h"
#include "wavelet/swt.h"
#include "wavelet/swt_analyze.h"
#include "wavelet/swt_synthesize.h"
#include "wavelet/tile.h"

namespace mcd::tool {
namespace {

// Taps of the filter at an even and an odd position: the analysis's, or the synthesis's.
std::pair<int, int> Taps(WaveletBasis basis, bool analysis) {
    if (basis == WaveletBasis::Cdf97) return analysis ? std::pair{9, 7} : std::pair{7, 9};
    if (basis == WaveletBasis::LeGall53) return analysis ? std::pair{5, 3} : std::pair{3, 5};
    return {1, 1};
}

// Every level's rows and columns passes walked position by position, a multiply and an
// add per tap plus `extra`.
double WalkedWaveletFlops(int width, int height, int channels, int levels, WaveletBasis basis,
                          bool analysis, double extra) {
    auto [evenTaps, oddTaps] = Taps(basis, analysis);
    double flops = 0;
    for (int level = 0; level < levels; ++level) {
        int w = LevelExtent(width, level), h = LevelExtent(height, level);
        for (int c = 0; c < channels; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    flops += 2 * (x % 2 == 0 ? evenTaps : oddTaps) + extra;  // rows pass
                    flops += 2 * (y % 2 == 0 ? evenTaps : oddTaps) + extra;  // columns pass
                }
    }
    return flops;
}

// The transforms' dispatches as the recorder keeps them (split into interior and edge
// parts above WAVELET_SPLIT_LENGTH positions, whole below), their formulas summed per
// kernel, against the walk: each position of each level filtered once per pass.
TEST(KernelOps, WaveletPassesMatchTheirLoops) {
    vk::Context &context = test::TestContext();
    const int width = 300, height = 270, channels = 3, levels = 3;
    vk::GpuImage in(context, width, height, channels, "in"),
        coef(context, width, height, channels, "coef");
    WaveletTransform transform(context, width, height, channels);
    for (WaveletBasis basis :
         {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97}) {
        vk::Recorder recorder(context);
        transform.RecordAnalysis(recorder, basis, levels, in, coef);
        transform.RecordSqAnalysis(recorder, basis, levels, in, coef, 1.f, 1.f);
        transform.RecordSynthesis(recorder, basis, levels, coef, in);
        vk::KeepDispatches(true);
        recorder.Submit();
        vk::KeepDispatches(false);
        std::map<std::string, double> flops, bytes;
        int split = 0;
        for (const vk::KeptDispatch &d : vk::KeptDispatches()) {
            std::optional<double> f = KernelFlops(d);
            ASSERT_TRUE(f.has_value()) << d.timing.kernel;
            flops[d.timing.kernel] += *f;
            bytes[d.timing.kernel] += KernelTouchedBytes(d).value_or(-1e30);
            split += d.Spec(WAVELET_SPEC_PART, WAVELET_PART_ALL) != WAVELET_PART_ALL;
        }
        EXPECT_GT(split, 0) << "no pass ran in parts: the test covers less than it means to";
        int b = int(basis);
        EXPECT_EQ(flops["wavelet_analyze"],
                  WalkedWaveletFlops(width, height, channels, levels, basis, true, 0))
            << "basis " << b;
        EXPECT_EQ(flops["wavelet_sqanalyze"],
                  WalkedWaveletFlops(width, height, channels, levels, basis, true, 1))
            << "basis " << b;
        EXPECT_EQ(flops["wavelet_synthesize"],
                  WalkedWaveletFlops(width, height, channels, levels, basis, false, 0))
            << "basis " << b;
        // Each pass reads and writes each position of its level's region once.
        double touched = 0;
        for (int level = 0; level < levels; ++level)
            touched +=
                2.0 * LevelExtent(width, level) * LevelExtent(height, level) * channels * 8;
        for (const char *kernel :
             {"wavelet_analyze", "wavelet_sqanalyze", "wavelet_synthesize"})
            EXPECT_EQ(bytes[kernel], touched) << kernel << ", basis " << b;
    }
}

// swt.glsl's reaches (half lengths) of the analysis filters: low, high.
std::pair<int, int> SwtReach(int basis) {
    if (basis == MCD_WAVELET_CDF97) return {4, 3};
    if (basis == MCD_WAVELET_LEGALL53) return {2, 1};
    return {0, 0};
}

// swt_analyze.comp's Analyze at one position.
double WalkAnalyze(int basis, bool squared, bool transform) {
    if (!transform) return 0;
    if (basis == MCD_WAVELET_HAAR) return squared ? 3 : 6;  // 0.5 a + 0.5 b; two pairs
    auto [low, high] = SwtReach(basis);
    double walked = 0;
    for (int k = -low; k <= low; ++k) {
        walked += 2;                           // lo += tap * v
        if (std::abs(k) <= high) walked += 2;  // hi += tap * v
    }
    return walked;
}

// swt_analyze.comp over the recorded grid: 4 positions per invocation.
double WalkSwtAnalyze(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::WaveletSwtAnalyzePush>(d);
    int basis = d.Spec(WAVELET_SWT_SPEC_BASIS, MCD_WAVELET_CDF97);
    int axis = d.Spec(WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS);
    bool squared = d.Spec(WAVELET_SWT_ANALYZE_SPEC_SQUARED, 0) != 0;
    bool tx = p.flags & WAVELET_SWT_TRANSFORM_X, ty = p.flags & WAVELET_SWT_TRANSFORM_Y;
    double walked = 0;
    ForEachInvocation(d, WAVELET_SWT_ANALYZE_LOCAL_SIZE, [&](int gx, int y, int) {
        int x0 = 4 * gx;
        if (x0 >= p.width || y >= p.height) return;
        for (int k = 0; k < std::min(4, p.width - x0); ++k) {
            if (axis == WAVELET_SWT_ROWS) walked += WalkAnalyze(basis, squared, tx);
            if (axis == WAVELET_SWT_COLUMNS) walked += 2 * WalkAnalyze(basis, squared, ty);
            if (axis == WAVELET_SWT_FUSED)  // r0, r1 along x; l, hi along y
                walked +=
                    2 * WalkAnalyze(basis, squared, tx) + 2 * WalkAnalyze(basis, squared, ty);
        }
    });
    return walked;
}

// swt_synthesize.comp's Synthesize at position i.
double WalkSynthesize(int basis, int i, int step, bool transform) {
    if (!transform) return 0;
    if (basis == MCD_WAVELET_HAAR) return i < step ? 3 : 3 + 5;
    auto [low, high] = SwtReach(basis);
    int synthLow = high, synthHigh = low, reach = std::max(synthLow, synthHigh);
    double walked = 0;
    for (int k = -reach; k <= reach; ++k) {
        if (std::abs(k) <= synthLow) walked += 2;
        if (std::abs(k) <= synthHigh) walked += 2;
    }
    return walked + 1;  // 0.5 * sum
}

double WalkSwtSynthesize(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::WaveletSwtSynthesizePush>(d);
    int basis = d.Spec(WAVELET_SWT_SPEC_BASIS, MCD_WAVELET_CDF97);
    bool rows = d.Spec(WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS) == WAVELET_SWT_ROWS;
    bool tx = p.flags & WAVELET_SWT_TRANSFORM_X, ty = p.flags & WAVELET_SWT_TRANSFORM_Y;
    double walked = 0;
    ForEachInvocation(d, WAVELET_SWT_SYNTHESIZE_LOCAL_SIZE, [&](int gx, int y, int) {
        int x0 = 4 * gx;
        if (x0 >= p.width || y >= p.height) return;
        for (int k = 0; k < std::min(4, p.width - x0); ++k)
            walked += rows ? WalkSynthesize(basis, x0 + k, p.step, tx)
                           : 2 * WalkSynthesize(basis, y, p.step, ty);
    });
    return walked;
}

// The float offsets an SWT pass reads (its source planes, every tap folded into the line)
// and writes, distinct, 4 bytes each: what it touches of the buffers it binds.
double WalkSwtTouched(const vk::KeptDispatch &d) {
    bool analysis = d.timing.kernel == "wavelet_swt_analyze";
    auto p = PushOf<shader::WaveletSwtAnalyzePush>(d);  // both pushes begin alike
    int axis = d.Spec(WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS);
    int plane = p.width * p.height;
    std::set<int64_t> read, written;
    for (uint32_t c = 0; c < d.timing.groups[2]; ++c)
        for (int at = 0; at < plane; ++at) {
            int64_t src = int64_t(c) * p.srcChannel + p.srcBase;
            int64_t dst = int64_t(c) * p.dstChannel + p.dstBase;
            int64_t dstLow = int64_t(c) * p.dstChannel + p.dstLow;
            int64_t srcLow = int64_t(c) * p.srcChannel + p.srcLow;
            if (analysis && axis == WAVELET_SWT_ROWS) {
                read.insert(src + at);
                written.insert(dst + at), written.insert(dst + plane + at);
            } else if (analysis) {  // columns (from two planes) and fused (from one)
                read.insert(src + at);
                if (axis == WAVELET_SWT_COLUMNS) read.insert(src + plane + at);
                written.insert(dstLow + at);
                for (int k = 0; k < 3; ++k) written.insert(dst + k * plane + at);
            } else if (axis == WAVELET_SWT_COLUMNS) {
                read.insert(srcLow + at);
                for (int k = 0; k < 3; ++k) read.insert(src + k * plane + at);
                written.insert(dst + at), written.insert(dst + plane + at);
            } else {
                read.insert(src + at), read.insert(src + plane + at);
                written.insert(dst + at);
            }
        }
    return 4.0 * double(read.size() + written.size());
}

// Every level's passes of the stationary transform for each basis, the variance analysis
// (squared taps) and the synthesis, on 37x13x3 at 5 levels (the columns stop transforming
// at level 4: 16 > 13), as SwtTransform records them.
TEST(KernelOps, SwtPassesMatchTheirLoops) {
    vk::Context &context = test::TestContext();
    const int width = 37, height = 13, channels = 3, levels = 5;
    vk::GpuImage in(context, width, height, channels, "in");
    SwtTransform transform(context, width, height, channels, levels);
    vk::GpuImage coef = transform.MakeCoefficients("coef");
    for (WaveletBasis basis :
         {WaveletBasis::Haar, WaveletBasis::LeGall53, WaveletBasis::Cdf97}) {
        vk::Recorder recorder(context);
        transform.RecordAnalysis(recorder, basis, in, coef);
        transform.RecordAnalysis(recorder, basis, in, coef, true);
        transform.RecordSynthesis(recorder, basis, coef, in);
        vk::KeepDispatches(true);
        recorder.Submit();
        vk::KeepDispatches(false);
        std::vector<vk::KeptDispatch> kept = vk::KeptDispatches();
        SCOPED_TRACE("basis " + std::to_string(int(basis)));
        ExpectFormulaMatchesWalk(kept, "wavelet_swt_analyze", WalkSwtAnalyze);
        ExpectFormulaMatchesWalk(kept, "wavelet_swt_synthesize", WalkSwtSynthesize);
        for (const vk::KeptDispatch &d : kept)
            EXPECT_EQ(KernelTouchedBytes(d).value_or(-1), WalkSwtTouched(d)) << d.timing.label;
    }
}

// awr/shrink.comp as RecordAwrShrink records it on a 37x29x3 image whose kept low-low band
// is 5x4: sqrt, cs *, |w| - t, max, sign * per coefficient outside that band.
TEST(KernelOps, AwrShrinkMatchesItsLoops) {
    vk::Context &context = test::TestContext();
    vk::GpuImage coef(context, 37, 29, 3, "coef"), variance(context, 37, 29, 3, "variance");
    vk::Recorder recorder(context);
    RecordAwrShrink(context, recorder, coef, variance, 5, 4, 1.f);
    vk::KeepDispatches(true);
    recorder.Submit();
    vk::KeepDispatches(false);
    ExpectFormulaMatchesWalk(vk::KeptDispatches(), "awr_shrink", [](const vk::KeptDispatch &d) {
        auto p = PushOf<shader::AwrShrinkPush>(d);
        double walked = 0;
        ForEachInvocation(d, AWR_SHRINK_LOCAL_SIZE, [&](int x, int y, int) {
            if (x >= p.width || (x < p.lowWidth && y < p.lowHeight)) return;
            walked += 5;
        });
        return walked;
    });
}

// bayes's Shrink on its costlier path (past the table): |v| / b, asinh, / du, sinh,
// last * du, b *, a -, table +.
constexpr double kWalkedShrink = 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1;

// bayes/shrink.comp (the DWT's, band of each coefficient by model.glsl's BayesBandOf) and
// swt_shrink.comp (4 coefficients of a row per invocation, one detail band per layer).
TEST(KernelOps, BayesShrinkMatchesItsLoops) {
    ExpectFormulaMatchesWalk(
        MethodDispatches("bayes", "dwt", [](Method &m) { m.Set("bayes-transform", "dwt"); }),
        "bayes_shrink", [](const vk::KeptDispatch &d) {
            auto p = PushOf<shader::BayesShrinkPush>(d);
            double walked = 0;
            ForEachInvocation(d, BAYES_SHRINK_LOCAL_SIZE, [&](int x, int y, int) {
                if (x >= p.width) return;
                int w = p.width, h = p.height;
                for (int level = 0; level < p.levels; ++level) {
                    int lowW = (w + 1) / 2, lowH = (h + 1) / 2;
                    if (x >= lowW || y >= lowH) {
                        walked += kWalkedShrink;
                        return;
                    }
                    w = lowW, h = lowH;
                }
            });
            return walked;
        });
    ExpectFormulaMatchesWalk(
        MethodDispatches("bayes", "swt", [](Method &m) { m.Set("bayes-transform", "swt"); }),
        "bayes_swt_shrink", [](const vk::KeptDispatch &d) {
            auto p = PushOf<shader::BayesSwtShrinkPush>(d);
            double walked = 0;
            ForEachInvocation(d, BAYES_SWT_SHRINK_LOCAL_SIZE, [&](int gx, int y, int) {
                for (int k = 0; k < 4 && 4 * gx + k < p.width && y < p.height; ++k)
                    walked += kWalkedShrink;
            });
            return walked;
        });
}

// rhf/distance.comp's CentreDistance, no pair vetoed.
double WalkCentreDistance(int x, int y, int ox, int oy, int pw, int w, int h) {
    int qx = x + ox, qy = y + oy;
    int w0 = std::min(std::min(pw, std::min(x, y)), std::min(w - 1 - x, h - 1 - y));
    if (qx < w0 || qx > w - 1 - w0 || qy < w0 || qy > h - 1 - w0) return 0;
    double walked = 0;
    for (int ty = -w0; ty <= w0; ++ty)
        for (int tx = -w0; tx <= w0; ++tx) walked += 2;  // sum, count
    return walked + 2;                                   // count + 1e-4, the divide
}

// rhf/distance.comp over the recorded grid, lane by lane as main() runs, no pair vetoed.
double WalkRhfDistance(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::RhfDistancePush>(d);
    const int pix = RHF_DISTANCE_PIXELS_PER_LANE;
    const int b = d.Spec(RHF_DISTANCE_SPEC_SEARCH_HALF, 6),
              pw = d.Spec(RHF_DISTANCE_SPEC_PATCH_HALF, 1);
    const int w = p.width, h = p.height, side = 2 * b + 1;
    double walked = 0;
    ForEachInvocation(d, RHF_DISTANCE_LOCAL_SIZE, [&](int gx, int r, int o) {
        int x0 = gx * pix, ox = o % side - b, oy = o / side - b, y = p.rowBase + r, qy = y + oy;
        if (x0 >= w) return;
        if (!(y >= pw && y <= h - 1 - pw && qy >= pw && qy <= h - 1 - pw)) {
            for (int j = 0; j < pix && x0 + j < w; ++j)
                walked += WalkCentreDistance(x0 + j, y, ox, oy, pw, w, h);
            return;
        }
        for (int ty = -pw; ty <= pw; ++ty)
            for (int j = 0; j < pix; ++j)
                for (int tx = 0; tx <= 2 * pw; ++tx) walked += 2;  // sum, count
        for (int j = 0; j < pix; ++j) {
            int x = x0 + j, qx = x + ox;
            bool fits = qx >= pw && qx <= w - 1 - pw;
            if (x >= pw && x <= w - 1 - pw && fits) walked += 2;
        }
        int left = std::clamp(pw - x0, 0, pix), end = std::min(pix, w - x0);
        int right = std::max(std::clamp(w - pw - x0, 0, pix), left);
        int border = left + std::max(end - right, 0);
        for (int i = 0; i < border; ++i) {
            int j = i < left ? i : right + i - left;
            walked += WalkCentreDistance(x0 + j, y, ox, oy, pw, w, h);
        }
    });
    return walked;
}

// terms.comp's AddTerms for the lane at x0: per pair `both`, and the term's 9 more where
// pixel and candidate are in the frame (Bin makes the others fail h_p + h_q > 1).
double WalkAddTerms(int x0, int width, int b) {
    double walked = 0;
    for (int j = 0; j < RHF_TERMS_PIXELS_PER_LANE; ++j)
        for (int k = 0; k < 2 * b + 1; ++k) {
            walked += 1;
            int qx = x0 + j + k - b;
            if (x0 + j < width && qx >= 0 && qx < width) walked += 9;
        }
    return walked;
}

// terms.comp, every bin plane marked by MayCount and every pair counted.
double WalkRhfTerms(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::RhfTermsPush>(d);
    const int pix = RHF_TERMS_PIXELS_PER_LANE, b = d.Spec(RHF_TERMS_SPEC_SEARCH_HALF, 6);
    const int span = pix + 2 * b, qb = (b + pix - 1) / pix;
    double walked = 0;
    ForEachInvocation(d, RHF_TERMS_LOCAL_SIZE, [&](int gx, int r, int dy) {
        int x0 = gx * pix, qy = p.rowBase + r + dy;
        if (x0 >= p.width || qy < 0 || qy >= p.height) return;
        double counts = 0;  // Count's scaling of the pixels and candidates inside
        for (int j = 0; j < pix; ++j) counts += x0 + j < p.width;
        for (int m = 0; m < span; ++m) counts += x0 + m - b >= 0 && x0 + m - b < p.width;
        walked += counts;
        // Each plane once: the saturated ones in MarkVetoedPairs (with the veto), the rest
        // in ACCUMULATE; MayCount's maxima and sum, Bin's scaling, AddTerms.
        for (int plane = 0; plane < p.binPlanes; ++plane)
            walked += (2 * qb + 1) + 1 + counts + WalkAddTerms(x0, p.width, b);
        if (p.brightVeto > 0)
            for (int i = 0; i < pix * (2 * b + 1); ++i) walked += 5;  // harmonic, its scale
    });
    return walked;
}

TEST(KernelOps, RhfFormulasMatchTheirLoops) {
    for (float veto : {0.f, 2.f}) {
        SCOPED_TRACE("bright veto " + std::to_string(veto));
        const std::vector<vk::KeptDispatch> &run = MethodDispatches(
            "rhf", std::to_string(veto), [veto](Method &m) { m.Set("bright-veto", veto); });
        ExpectFormulaMatchesWalk(run, "rhf_distance", WalkRhfDistance);
        ExpectFormulaMatchesWalk(run, "rhf_terms", WalkRhfTerms);
    }
}

// pivot/fit.comp's pieces: weightAt (geometric term, exponent, distance term where the
// radius is positive, exp and product), addSample with sumZ, a Moments sum, solve.
struct PivotWalk {
    const shader::PivotFitPush &p;
    bool normals;
    double walked = 0;

    double Weight(bool final) const {
        double geometric = (normals ? 5 + 3 : 0) + 1;  // dot, d^4; normal * ids
        return geometric + 6 + (final ? 6 : 0) + 2;
    }
    // rowSums / columnSums over a clipped segment, then the plus() into a part.
    void Row(int y, int xa, int xb, bool final) {
        if (y >= 0 && y < p.height)
            for (int x = std::max(xa, 0); x <= std::min(xb, p.width - 1); ++x)
                walked += Weight(final) + 20 + 1;
    }
    void Column(int x, int ya, int yb) {
        if (x >= 0 && x < p.width)
            for (int y = std::max(ya, 0); y <= std::min(yb, p.height - 1); ++y)
                walked += Weight(false) + 20 + 1;
    }
    void Ring(int x0, int y0, int r) {
        if (r == 0) {
            Row(y0, x0, x0, false), walked += 10;
            return;
        }
        for (int y : {y0 - r, y0 + r}) {
            Row(y, x0 - r, x0 - 1, false), Row(y, x0, x0, false), Row(y, x0 + 1, x0 + r, false);
            walked += 3 * 10;
        }
        for (int x : {x0 - r, x0 + r}) {
            Column(x, y0 - r + 1, y0 - 1), Column(x, y0, y0), Column(x, y0 + 1, y0 + r - 1);
            walked += 3 * 10;
        }
    }
    static constexpr double kSolve = 39;
    // The square's solve (its 8 sums), each quadrant's (3 sums) with disagrees (5).
    void Solves() {
        walked += 8 * 10 + kSolve;
        for (int m = 0; m < 4; ++m) walked += 3 * 10 + kSolve + 5;
    }
    void Centre(int x0, int y0) {
        for (int v = std::max(0, y0 - 1); v <= std::min(p.height - 1, y0 + 1); ++v)
            for (int u = std::max(0, x0 - 1); u <= std::min(p.width - 1, x0 + 1); ++u)
                walked += 1;
        walked += 1;  // zc / n
        int radius = 2;
        for (int r = 0;; ++r) {
            Ring(x0, y0, r);
            if (r < 2) continue;
            Solves();
            walked += 2;  // quiet
            bool covers =
                x0 - r <= 0 && y0 - r <= 0 && x0 + r >= p.width - 1 && y0 + r >= p.height - 1;
            int step = 1;  // lattice.glsl at radius r + 1
            while (step < PIVOT_LATTICE_MAX_STEP && 2 * step <= (r + 1) / 2.0) step *= 2;
            if (covers || r >= p.maxRadius || x0 % step != 0 || y0 % step != 0) {
                radius = r;
                break;
            }
        }
        walked += 1;  // mean
        // fitAndStore at the radius, for every centre (the bound).
        for (int y = std::max(0, y0 - radius); y <= std::min(p.height - 1, y0 + radius); ++y) {
            Row(y, x0 - radius, x0 - 1, true), Row(y, x0, x0, true);
            Row(y, x0 + 1, x0 + radius, true);
            if (y != y0) walked += 3 * 10;
        }
        walked += 8 * 10 + kSolve;                              // the square
        for (int m = 0; m < 4; ++m) walked += 3 * 10 + kSolve;  // storeFits
    }
};

// The column of invocation i in its workgroup's row segment (fit.comp's columnOf).
int PivotColumnOf(int i) {
    if (i < 8) return i * 8;
    if (i < 16) return (i - 8) * 8 + 4;
    if (i < 32) return (i - 16) * 4 + 2;
    return (i - 32) * 2 + 1;
}

// pivot/fit.comp over pivot's recorded dispatches, every centre growing until the lattice,
// the frame or maxRadius stops it, each weight non-zero and each solve of full rank.
TEST(KernelOps, PivotFitMatchesItsLoops) {
    ExpectFormulaMatchesWalk(MethodDispatches("pivot"), "pivot_fit",
                             [](const vk::KeptDispatch &d) {
                                 auto p = PushOf<shader::PivotFitPush>(d);
                                 PivotWalk walk{p, d.Spec(PIVOT_SPEC_NORMALS, 0) != 0};
                                 ForEachInvocation(d, PIVOT_LOCAL_SIZE, [&](int x, int y, int) {
                                     int x0 = x / PIVOT_LOCAL_SIZE * PIVOT_LOCAL_SIZE +
                                              PivotColumnOf(x % PIVOT_LOCAL_SIZE);
                                     if (x0 < p.width) walk.Centre(x0, p.rowBase + y);
                                 });
                                 return walk.walked;
                             });
}

// A kernel without a formula says so instead of counting nothing; a formula that takes no
// data-dependent shortcut says it bounds the work.
TEST(KernelOps, KernelWithoutFormulaHasNone) {
    vk::KeptDispatch d;
    d.timing.kernel = "pivot_gather";
    EXPECT_FALSE(KernelFlops(d).has_value());
    EXPECT_TRUE(KernelFlopsRule("pivot_gather").empty());
    EXPECT_FALSE(KernelFlopsRule("rhf_distance").empty());
    EXPECT_EQ(KernelFlopsBound("nfor_regress"), OpsBound::AtMost);
    EXPECT_EQ(KernelFlopsBound("wavelet_swt_analyze"), OpsBound::Exact);
}

}  // namespace
}  // namespace mcd::tool
