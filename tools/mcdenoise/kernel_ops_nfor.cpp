// nfor's operation formulas, one place: each names the shader loops it counts, so that a
// change to those loops (shaders/nfor/) is followed here and in the walks of
// tests/tools/kernel_ops_test.cpp. Rules as in kernel_ops.h.
#include <cstdlib>

#include "nfor/distance.h"
#include "nfor/fit.h"
#include "nfor/nfor.h"
#include "nfor/noise.h"
#include "nfor/prefilter.h"
#include "tools/mcdenoise/kernel_ops_formulas.h"

namespace mcd::tool {
namespace {

int Channels(const vk::KeptDispatch &d) {
    return d.Spec(NFOR_SPEC_CHANNELS, 3);
}

// prefilter.comp, per invocation (pixel, plane z): 1 / bandwidth^2 (2) and the final
// divide (1); per window step in the frame: the distance's divide, max, scale (3), the
// weighted sum (2) and the weight sum (1), and an exp off the centre; per patch step with
// both ends inside: the term's 11 operators, min and the sum (14).
double PrefilterFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforPrefilterPush>(d);
    double pixels = double(p.width) * p.height;
    double steps = WindowPairs(p.width, p.radius) * WindowPairs(p.height, p.radius);
    double patch = PatchTriples(p.width, p.radius, p.patchRadius) *
                   PatchTriples(p.height, p.radius, p.patchRadius);
    return d.timing.groups[2] * (3 * pixels + 6 * steps + (steps - pixels) + 14 * patch);
}

// offsets.glsl's storedOffset: stored offset j of a window of half-size `radius`.
std::pair<int, int> StoredOffset(int radius, int j) {
    int side = 2 * radius + 1, index = (side * side + 1) / 2 + j;
    return {index % side - radius, index / side - radius};
}

// term.comp, per invocation whose q = p + o is inside: per channel the difference (1), the
// variance sum (1, or 2 min: 2), the term's 10 operators, min and the sum (2), and with an
// albedo valueAt's divide, square and divide at p and q (6); then the mean's divide (1).
double TermFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforDistancePush>(d);
    double perChannel = 1 + (p.minVariance ? 2 : 1) + 10 + 2 + (p.albedoChannels > 0 ? 6 : 0);
    double perInside = Channels(d) * perChannel + 1, flops = 0;
    for (uint32_t j = 0; j < d.timing.groups[2]; ++j) {
        auto [ox, oy] = StoredOffset(p.radius, int(j));
        double inside =
            double(std::max(0, p.width - std::abs(ox))) * std::max(0, p.height - std::abs(oy));
        flops += perInside * inside;
    }
    return flops;
}

// box.comp's along(): whether a patch position t in [-f, f] has x + t and x + o + t in
// [0, n); the positions x of a line where one has.
double PositionsWithPatch(int n, int o, int f) {
    double count = 0;
    for (int x = 0; x < n; ++x) {
        int lo = std::max(-f, std::max(-x, -x - o)),
            hi = std::min(f, std::min(n - 1 - x, n - 1 - x - o));
        count += hi >= lo;
    }
    return count;
}

// box.comp: an add per patch position inside along the pass's axis; the columns pass
// (vertical 1) divides where the patch has a position with both ends inside.
double BoxFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforDistancePush>(d);
    double flops = 0;
    for (uint32_t j = 0; j < d.timing.groups[2]; ++j) {
        if (p.vertical == 0) {
            flops += p.height * WindowPairs(p.width, p.patchRadius);
            continue;
        }
        auto [ox, oy] = StoredOffset(p.radius, int(j));
        flops += p.width * WindowPairs(p.height, p.patchRadius) +
                 PositionsWithPatch(p.width, ox, p.patchRadius) *
                     PositionsWithPatch(p.height, oy, p.patchRadius);
    }
    return flops;
}

// regress.comp with weight.glsl, columns C = features + 3, per window step in the frame:
// weightOf's two scaled offsets (2), per feature the difference, weight and square-add (4),
// off the centre the distance's max, scale, add and exp (4); ACCUMULATE's row i: wx (1),
// its i + 1 products into the triangle (2 each), one per channel into b (2 each); the
// weight sum (1). Per pixel: the ridge (2 per column but the constant), the Cholesky
// (column j: 2j, sqrt, and per row below 2j + 1), per channel both triangular solves
// (2 C^2) and the influence (2i + 3 per row).
double RegressFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforFitPush>(d);
    double features = d.Spec(NFOR_SPEC_FEATURES, 7), c = features + 3, ch = Channels(d);
    double pixels = double(p.width) * p.height;
    double steps = WindowPairs(p.width, p.radius) * WindowPairs(p.height, p.radius);
    double perStep = 2 + 4 * features + c + c * (c + 1) + 2 * ch * c + 1;
    double cholesky = 0;
    for (int j = 0; j < c; ++j) cholesky += 2 * j + 1 + (c - 1 - j) * (2 * j + 1);
    double perPixel = 2 * (c - 1) + cholesky + 2 * c * c * ch + c * c + 2 * c;
    return steps * perStep + 4 * (steps - pixels) + pixels * perPixel;
}

// gather.comp with weight.glsl, per window step within gatherRadius in the frame: weightOf
// as in regress (2, 4 per feature, 4 off the centre), PREDICT's product-add per column and
// channel (2 each), the four weighted sums as written (8) and the weight sum (1); per pixel
// a divide per channel.
double GatherFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforFitPush>(d);
    double features = d.Spec(NFOR_SPEC_FEATURES, 7), c = features + 3, ch = Channels(d);
    double pixels = double(p.width) * p.height;
    double steps = WindowPairs(p.width, p.gatherRadius) * WindowPairs(p.height, p.gatherRadius);
    double perStep = 2 + 4 * features + 2 * ch * c + 8 + 1;
    return steps * perStep + 4 * (steps - pixels) + pixels * ch;
}

// noise.comp's directions d.
constexpr int kNoiseDirections[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};

// noise.comp's pairs along one axis at position x: window positions u in [0, n) whose
// neighbour u + s is in [0, n) too.
int NoisePairs(int x, int r, int s, int n) {
    int lo = std::max(x - r, std::max(0, -s)), hi = std::min(x + r, std::min(n - 1, n - 1 - s));
    return std::max(0, hi - lo + 1);
}

// noise.comp, per invocation (pixel, channel z): per direction and window pair with both
// pixels inside the difference, half its square (3) and, with a divisor, alike's two
// products twice and zAt's two divides (6); per direction with a pair the estimate's
// divide (1); with a divisor the pixel's square (1); where some direction has a pair the
// output's two products.
double NoiseFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforNoisePush>(d);
    bool divisor = p.divisorChannels > 0;
    double perPair = 3 + (divisor ? 6 : 0), flops = 0;
    double outputs = 0;
    for (int x = 0; x < p.width; ++x)
        for (int y = 0; y < p.height; ++y) {
            double estimates = 0;
            for (auto [dx, dy] : kNoiseDirections) {
                double pairs = double(NoisePairs(x, p.radius, dx, p.width)) *
                               NoisePairs(y, p.radius, dy, p.height);
                flops += perPair * pairs;
                estimates += pairs > 0;
            }
            flops += estimates;
            outputs += estimates > 0;
        }
    double pixels = double(p.width) * p.height;
    return (flops + 2 * outputs + (divisor ? pixels : 0)) * d.timing.groups[2];
}

}  // namespace

const FormulaMap &NforFormulas() {
    static const FormulaMap formulas = {
        {"nfor_prefilter",
         {"per window step 6 (+ exp off the centre), per patch step 14, per pixel 3; every "
          "weight under the cut",
          PrefilterFlops, OpsBound::AtMost}},
        {"nfor_term",
         {"per offset with q inside, per channel 14 (15 min-variance, +6 albedo-divided, "
          "every albedo above the floor) and 1",
          TermFlops, OpsBound::AtMost}},
        {"nfor_noise",
         {"per direction and window pair inside 3 (+6 with a divisor), per direction with a "
          "pair 1, per pixel 2 where one has a pair (+1 with a divisor); every pair alike, "
          "every "
          "divisor above the floor",
          NoiseFlops, OpsBound::AtMost}},
        {"nfor_box", {"an add per patch position inside; the columns pass a divide", BoxFlops}},
        {"nfor_regress",
         {"per window step 3 + 4F + C(C+2) + 2C channels (+4 off the centre), per pixel the "
          "ridge, Cholesky and solves (C = F + 3); no emitter or zero weight",
          RegressFlops, OpsBound::AtMost}},
        {"nfor_gather",
         {"per gather step 11 + 4F + 2C channels (+4 off the centre), per pixel a divide per "
          "channel; no emitter or zero weight",
          GatherFlops, OpsBound::AtMost}},
    };
    return formulas;
}

}  // namespace mcd::tool
