// nfor's operation formulas (tools/mcdenoise/kernel_ops_nfor.cpp) against walks of its
// shaders' loops (shaders/nfor/) over the dispatches an nfor run records: each walk steps
// through the invocations of the recorded grid and the loops as the shader writes them,
// adding each statement's operators (rules in kernel_ops.h) where the shader runs it. A
// change to those loops changes the walk here and the formula there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>

#include "nfor/distance.h"
#include "nfor/fit.h"
#include "nfor/nfor.h"
#include "nfor/noise.h"
#include "nfor/prefilter.h"
#include "tests/tools/kernel_ops_walk.h"

namespace mcd::tool {
namespace {

bool Inside(int x, int y, int w, int h) {
    return x >= 0 && y >= 0 && x < w && y < h;
}

// prefilter.comp.
double WalkPrefilter(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforPrefilterPush>(d);
    int w = p.width, h = p.height, r = p.radius, f = p.patchRadius;
    double walked = 0;
    ForEachInvocation(d, NFOR_LOCAL_SIZE, [&](int x, int y, int) {
        if (x >= w) return;
        walked += 2;  // scale
        for (int v = y - r; v <= y + r; ++v)
            for (int u = x - r; u <= x + r; ++u) {
                if (!Inside(u, v, w, h)) continue;
                for (int ty = -f; ty <= f; ++ty)
                    for (int tx = -f; tx <= f; ++tx)
                        if (Inside(x + tx, y + ty, w, h) && Inside(u + tx, v + ty, w, h))
                            walked += 14;           // the term (12), min, the distance's sum
                walked += 3;                        // distance / count, max, * scale
                if (u != x || v != y) walked += 1;  // exp
                walked += 3;                        // the weighted sum, the weights' sum
            }
        walked += 1;  // sum / weights
    });
    return walked;
}

std::pair<int, int> Offset(int radius, int j) {
    int side = 2 * radius + 1, index = (side * side + 1) / 2 + j;
    return {index % side - radius, index / side - radius};
}

// term.comp.
double WalkTerm(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforDistancePush>(d);
    int channels = d.Spec(NFOR_SPEC_CHANNELS, 3);
    double walked = 0;
    ForEachInvocation(d, NFOR_LOCAL_SIZE, [&](int x, int y, int z) {
        if (x >= p.width) return;
        for (int k = 0; k < NFOR_TERM_OFFSETS; ++k) {
            auto [ox, oy] = Offset(p.radius, z * NFOR_TERM_OFFSETS + k);
            if (!Inside(x + ox, y + oy, p.width, p.height)) continue;
            for (int c = 0; c < channels; ++c) {
                walked += 1;                           // diff
                walked += p.minVariance != 0 ? 2 : 1;  // s
                walked += 10;                          // t
                walked += 2;                           // min, the sum
            }
            walked += 1;  // the mean
        }
    });
    return walked;
}

// box.comp.
int Along(int x, int o, int f, int n) {
    int lo = std::max(-f, std::max(-x, -x - o)),
        hi = std::min(f, std::min(n - 1 - x, n - 1 - x - o));
    return std::max(0, hi - lo + 1);
}

double WalkBox(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforDistancePush>(d);
    int w = p.width, h = p.height, f = p.patchRadius;
    double walked = 0;
    // An invocation sums NFOR_BOX_BLOCK outputs of a group of NFOR_TERM_OFFSETS offsets
    // along its pass's axis: each add a vec4's, one per offset.
    ForEachInvocation(d, NFOR_LOCAL_SIZE, [&](int gx, int gy, int group) {
        for (int k = 0; k < NFOR_BOX_BLOCK; ++k) {
            int x = p.vertical == 0 ? gx * NFOR_BOX_BLOCK + k : gx,
                y = p.vertical == 0 ? gy : gy * NFOR_BOX_BLOCK + k;
            if (x >= w || y >= h) return;
            if (p.vertical == 0) {
                for (int t = std::max(-f, -x); t <= std::min(f, w - 1 - x); ++t)
                    walked += NFOR_TERM_OFFSETS;
                continue;
            }
            for (int t = std::max(-f, -y); t <= std::min(f, h - 1 - y); ++t)
                walked += NFOR_TERM_OFFSETS;
            for (int c = 0; c < NFOR_TERM_OFFSETS; ++c) {
                auto [ox, oy] = Offset(p.radius, group * NFOR_TERM_OFFSETS + c);
                if (Along(x, ox, f, w) * Along(y, oy, f, h) > 0) walked += 1;
            }
        }
    });
    return walked;
}

// weight.glsl's weightOf, the weight not zero.
double WalkWeightOf(int features, bool centre) {
    double walked = 2;                               // col[1], col[2]
    for (int j = 0; j < features; ++j) walked += 4;  // d, s, e += s * s
    if (!centre) walked += 4;                        // max, * invBandwidth2, e +=, exp
    return walked;
}

// regress.comp after the window: ridge, Cholesky, the solves and the influence.
double WalkSolve(int columns, int channels) {
    double walked = 0;
    for (int i = 1; i < columns; ++i) walked += 2;
    for (int j = 0; j < columns; ++j) {
        for (int k = 0; k < j; ++k) walked += 2;
        walked += 1;  // sqrt
        for (int i = j + 1; i < columns; ++i) {
            for (int k = 0; k < j; ++k) walked += 2;
            walked += 1;  // t / l
        }
    }
    for (int c = 0; c < channels; ++c) {
        for (int i = 0; i < columns; ++i) {
            for (int k = 0; k < i; ++k) walked += 2;
            walked += 1;
        }
        for (int i = columns - 1; i >= 0; --i) {
            for (int k = i + 1; k < columns; ++k) walked += 2;
            walked += 1;
        }
    }
    for (int i = 0; i < columns; ++i) {
        for (int k = 0; k < i; ++k) walked += 2;
        walked += 1 + 2;  // z, influence += z * z
    }
    return walked;
}

// regress.comp, every pixel unmasked and every weight non-zero.
double WalkRegress(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforFitPush>(d);
    int channels = d.Spec(NFOR_SPEC_CHANNELS, 3), features = d.Spec(NFOR_SPEC_FEATURES, 7);
    int columns = features + 3, r = p.radius, candidates = d.Spec(NFOR_SPEC_CANDIDATES, 1);
    double walked = 0;
    ForEachInvocation(d, NFOR_LOCAL_SIZE, [&](int x, int y, int) {
        if (x >= p.width) return;
        for (int v = y - r; v <= y + r; ++v)
            for (int u = x - r; u <= x + r; ++u) {
                if (!Inside(u, v, p.width, p.height)) continue;
                bool centre = u == x && v == y;
                walked += WalkWeightOf(features, centre);
                // The second candidate's weight: * its 1 / k^2, e +, exp.
                if (candidates > 1 && !centre) walked += 3;
                for (int k = 0; k < candidates; ++k) {
                    for (int i = 0; i < columns; ++i) {  // ACCUMULATE
                        walked += 1;                     // wx
                        for (int j = 0; j <= i; ++j) walked += 2;
                        for (int c = 0; c < channels; ++c) walked += 2;
                    }
                    walked += 1;  // weights
                }
            }
        for (int k = 0; k < candidates; ++k) walked += WalkSolve(columns, channels);
    });
    return walked;
}

// gather.comp, every pixel unmasked and every weight non-zero.
double WalkGather(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforFitPush>(d);
    int channels = d.Spec(NFOR_SPEC_CHANNELS, 3), features = d.Spec(NFOR_SPEC_FEATURES, 7);
    int columns = features + 3, r = p.gatherRadius;
    double walked = 0;
    ForEachInvocation(d, NFOR_LOCAL_SIZE, [&](int x, int y, int) {
        if (x >= p.width) return;
        for (int v = y - r; v <= y + r; ++v)
            for (int u = x - r; u <= x + r; ++u) {
                if (!Inside(u, v, p.width, p.height)) continue;
                walked += WalkWeightOf(features, u == x && v == y);
                for (int i = 0; i < columns; ++i)  // PREDICT
                    for (int c = 0; c < channels; ++c) walked += 2;
                walked += 4 * 2 + 1;  // sum0..sum3, weights
            }
        for (int c = 0; c < channels; ++c) walked += 1;
    });
    return walked;
}

// noise.comp's smallestMedian at (x, y): the operators it runs where `counts(n, centre)`
// says whether a pair counts (n: those counted so far in the direction; centre: the pixel
// is in it) and each pair's alike tests cost `alike` (the relaxed scan's tests have none).
// Whether a direction had minPairs.
bool WalkSmallestMedian(const shader::NforNoisePush &p, int x, int y, bool relaxed,
                        int minPairs, double alike,
                        const std::function<bool(int, bool)> &counts, double &walked) {
    const int dirs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    bool divisor = p.divisorChannels > 0;
    int r = p.radius;
    bool best = false;
    for (auto [dx, dy] : dirs) {
        int n = 0;
        for (int v = y - r; v <= y + r; ++v)
            for (int u = x - r; u <= x + r; ++u) {
                int u1 = u + dx, v1 = v + dy;
                if (!Inside(u, v, p.width, p.height) || !Inside(u1, v1, p.width, p.height))
                    continue;
                bool centre = (u == x && v == y) || (u1 == x && v1 == y);
                if (!relaxed) walked += alike;  // counts' alike(a, a0) && alike(a, a1)
                if (!counts(n, centre)) continue;
                if (divisor) walked += 2;  // zAt's divides
                walked += 1 + 2;           // diff, 0.5 * diff * diff
                ++n;
            }
        if (n < minPairs) continue;
        walked += 1;  // the estimate
        best = true;
    }
    return best;
}

// noise.comp's main after the scans: the scale with a divisor, the output's products.
double WalkNoiseOutput(bool divisor, bool best) {
    return (divisor ? 1 : 0) + (best ? 2 : 0);
}

// noise.comp, every divisor above the floor, the costlier of two paths: every pair alike
// (each alike a product twice), the relaxed scan where no direction had enough; and, with
// `relaxed` and a divisor, each pair's alike tests both run but too few pairs alike in
// every direction, then the relaxed scan.
double WalkNoise(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforNoisePush>(d);
    bool divisor = p.divisorChannels > 0;
    double alike = divisor ? 2 * 2 : 0;
    auto everyPair = [](int, bool) { return true; };
    auto offCentre = [](int, bool centre) { return !centre; };
    auto tooFew = [](int n, bool) { return n + 1 < NFOR_NOISE_MIN_PAIRS; };
    double walked = 0;
    ForEachInvocation(d, NFOR_LOCAL_SIZE, [&](int x, int y, int) {
        if (x >= p.width) return;
        double strict = 0;
        bool best =
            WalkSmallestMedian(p, x, y, false, NFOR_NOISE_MIN_PAIRS, alike, everyPair, strict);
        if (!best && p.relaxed != 0)
            best = WalkSmallestMedian(p, x, y, true, NFOR_NOISE_MIN_RELAXED_PAIRS, 0, offCentre,
                                      strict);
        strict += WalkNoiseOutput(divisor, best);
        double fallback = 0;
        if (divisor && p.relaxed != 0) {
            best = WalkSmallestMedian(p, x, y, false, NFOR_NOISE_MIN_PAIRS, alike, tooFew,
                                      fallback);
            EXPECT_FALSE(best);
            best = WalkSmallestMedian(p, x, y, true, NFOR_NOISE_MIN_RELAXED_PAIRS, 0, offCentre,
                                      fallback);
            fallback += WalkNoiseOutput(divisor, best);
        }
        walked += std::max(strict, fallback);
    });
    return walked;
}

// `d` as if dispatched over a width x height frame (the noise kernel's grid: rows of
// NFOR_LOCAL_SIZE, one plane per channel).
vk::KeptDispatch NoiseOver(vk::KeptDispatch d, int width, int height) {
    shader::NforNoisePush p = PushOf<shader::NforNoisePush>(d);
    p.width = width, p.height = height;
    std::memcpy(d.push.data(), &p, sizeof(p));
    d.timing.groups[0] = (width + NFOR_LOCAL_SIZE - 1) / NFOR_LOCAL_SIZE;
    d.timing.groups[1] = height;
    return d;
}

TEST(KernelOps, NforFormulasMatchTheirLoops) {
    // A wider prefilter than the default (radius 1), with patches.
    const std::vector<vk::KeptDispatch> &run =
        MethodDispatches("nfor", "prefilter 3 1", [](Method &m) {
            m.Set("prefilter-radius", 3);
            m.Set("prefilter-patch", 1);
        });
    ExpectFormulaMatchesWalk(run, "nfor_prefilter", WalkPrefilter);
    ExpectFormulaMatchesWalk(run, "nfor_term", WalkTerm);
    ExpectFormulaMatchesWalk(run, "nfor_box", WalkBox);
    ExpectFormulaMatchesWalk(run, "nfor_box_columns", WalkBox);
    ExpectFormulaMatchesWalk(run, "nfor_regress", WalkRegress);
    ExpectFormulaMatchesWalk(run, "nfor_gather", WalkGather);
    // The prefilter's noise estimate of the features: no divisor.
    ExpectFormulaMatchesWalk(run, "nfor_noise", WalkNoise);
    const std::vector<vk::KeptDispatch> &plain =
        MethodDispatches("nfor", "no variance", nullptr, {"variance"});
    // The defaults: the prefilter over 3x3.
    ExpectFormulaMatchesWalk(plain, "nfor_prefilter", WalkPrefilter);
    ExpectFormulaMatchesWalk(plain, "nfor_term", WalkTerm);
    ExpectFormulaMatchesWalk(plain, "nfor_box", WalkBox);
    ExpectFormulaMatchesWalk(plain, "nfor_box_columns", WalkBox);
    ExpectFormulaMatchesWalk(plain, "nfor_regress", WalkRegress);
    ExpectFormulaMatchesWalk(plain, "nfor_gather", WalkGather);
    // A frame without a variance layer has its colour's noise estimated, divided by the
    // albedo, twice: strict for the firefly clamp, relaxed on the clamped colour for the
    // weights.
    ExpectFormulaMatchesWalk(plain, "nfor_noise", WalkNoise);
    int divided = 0, relaxed = 0;
    std::vector<vk::KeptDispatch> noise;
    for (const vk::KeptDispatch &d : plain) {
        if (d.timing.kernel != "nfor_noise") continue;
        auto p = PushOf<shader::NforNoisePush>(d);
        divided += p.divisorChannels > 0;
        relaxed += p.divisorChannels > 0 && p.relaxed != 0;
        noise.push_back(d);
    }
    EXPECT_GT(divided, 0) << "no noise estimate was divided by the albedo";
    EXPECT_GT(relaxed, 0) << "no relaxed noise estimate was recorded";
    // Frames so small that no direction has enough pairs: the relaxed scan runs at every
    // pixel of a relaxed dispatch, both with and without a divisor.
    std::vector<vk::KeptDispatch> tiny;
    for (const vk::KeptDispatch &d : noise)
        for (auto [w, h] : {std::pair{1, 1}, {2, 1}, {1, 3}, {2, 2}, {3, 2}, {4, 4}}) {
            tiny.push_back(NoiseOver(d, w, h));
            auto p = PushOf<shader::NforNoisePush>(tiny.back());
            p.relaxed = 1;
            std::memcpy(tiny.back().push.data(), &p, sizeof(p));
        }
    ExpectFormulaMatchesWalk(tiny, "nfor_noise", WalkNoise);
}

}  // namespace
}  // namespace mcd::tool
