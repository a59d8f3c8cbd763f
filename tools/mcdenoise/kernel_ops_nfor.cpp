// nfor's operation formulas, one place: each names the shader loops it counts, so that a
// change to those loops (shaders/nfor/) is followed here and in the walks of
// tests/tools/kernel_ops_nfor_test.cpp. Rules as in kernel_ops.h.
#include <algorithm>
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

// term.comp, per pixel and offset (NFOR_TERM_OFFSETS an invocation) whose q = p + o is
// inside: per channel the difference (1), the variance sum (1, or 2 min: 2), the term's 10
// operators, min and the sum (2); then the mean's divide (1). The albedo's divides are
// illumination.comp's, once a pixel; a pair with an end whose albedo is not trusted
// multiplies back 6 more per channel, which depends on the data and is not counted.
double TermFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforDistancePush>(d);
    double perChannel = 1 + (p.minVariance ? 2 : 1) + 10 + 2;
    double perInside = Channels(d) * perChannel + 1, flops = 0;
    for (uint32_t j = 0; j < d.timing.groups[2] * NFOR_TERM_OFFSETS; ++j) {
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

// box.comp (rows) and box_columns.comp, per stored offset of the invocations' groups: an add
// per patch position inside along the pass's axis; the columns pass (vertical 1) divides
// where the patch has a position with both ends inside.
double BoxFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforDistancePush>(d);
    double flops = 0;
    for (uint32_t j = 0; j < d.timing.groups[2] * NFOR_TERM_OFFSETS; ++j) {
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
// (2 C^2) and the influence (2i + 3 per row). A second candidate in the pass
// (NFOR_SPEC_CANDIDATES 2) adds, off the centre, its weight's scale, add and exp (3), its own
// ACCUMULATE and weight sum per step and its own solve per pixel.
double RegressFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforFitPush>(d);
    double features = d.Spec(NFOR_SPEC_FEATURES, 7), c = features + 3, ch = Channels(d);
    double candidates = d.Spec(NFOR_SPEC_CANDIDATES, 1);
    double pixels = double(p.width) * p.height;
    double steps = WindowPairs(p.width, p.radius) * WindowPairs(p.height, p.radius);
    double perStep = 2 + 4 * features + candidates * (c + c * (c + 1) + 2 * ch * c + 1);
    double offCentre = 4 + 3 * (candidates - 1);
    double cholesky = 0;
    for (int j = 0; j < c; ++j) cholesky += 2 * j + 1 + (c - 1 - j) * (2 * j + 1);
    double perPixel = 2 * (c - 1) + cholesky + 2 * c * c * ch + c * c + 2 * c;
    return steps * perStep + offCentre * (steps - pixels) + candidates * pixels * perPixel;
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

// noise.comp at one pixel: the pairs along each direction, and those with the pixel in
// neither (the relaxed scan's).
struct NoiseWindow {
    int pairs[4], offCentre[4];
};

NoiseWindow NoiseWindowAt(int x, int y, const shader::NforNoisePush &p) {
    NoiseWindow window{};
    for (int d = 0; d < 4; ++d) {
        auto [dx, dy] = kNoiseDirections[d];
        int pairs =
            NoisePairs(x, p.radius, dx, p.width) * NoisePairs(y, p.radius, dy, p.height);
        // The pairs (x, y)-(x + d) and (x - d)-(x, y), where inside (the window holds both).
        auto in = [&](int u, int v) { return u >= 0 && v >= 0 && u < p.width && v < p.height; };
        window.pairs[d] = pairs;
        window.offCentre[d] = pairs - in(x + dx, y + dy) - in(x - dx, y - dy);
    }
    return window;
}

// noise.comp's relaxed scan with every pair off the centre counted: per pair the
// difference, half its square (3) and zAt's two divides with a divisor (2); per direction
// with NFOR_NOISE_MIN_RELAXED_PAIRS the estimate's divide. Whether one had them.
bool RelaxedScan(const NoiseWindow &window, bool divisor, double &flops) {
    bool best = false;
    for (int d = 0; d < 4; ++d) {
        int n = window.offCentre[d];
        flops += (3 + (divisor ? 2 : 0)) * double(n);
        if (n < NFOR_NOISE_MIN_RELAXED_PAIRS) continue;
        flops += 1;
        best = true;
    }
    return best;
}

// noise.comp at one pixel, the costlier of two paths (only the first without a divisor,
// where every pair is alike and it is exact): (a) every pair alike in the strict scan: per
// pair alike's two products twice (4, with a divisor), the difference, half its square and
// zAt's divides (3 + 2 with a divisor), per direction with NFOR_NOISE_MIN_PAIRS the
// estimate (1), the relaxed scan where none has them; (b) with `relaxed`, no direction with
// enough pairs alike: per pair alike's 4, at most NFOR_NOISE_MIN_PAIRS - 1 pairs counted per
// direction (5 each), then the relaxed scan. Then the pixel's square with a divisor (1) and
// the output's two products where an estimate was found.
double NoisePixelFlops(const NoiseWindow &window, const shader::NforNoisePush &p) {
    bool divisor = p.divisorChannels > 0;
    double alike = divisor ? 4 : 0, counted = 3 + (divisor ? 2 : 0);
    double strict = 0;
    bool best = false;
    for (int d = 0; d < 4; ++d) {
        int n = window.pairs[d];
        strict += (alike + counted) * n;
        if (n < NFOR_NOISE_MIN_PAIRS) continue;
        strict += 1;
        best = true;
    }
    if (!best && p.relaxed != 0) best = RelaxedScan(window, divisor, strict);
    strict += (divisor ? 1 : 0) + (best ? 2 : 0);
    if (!divisor || p.relaxed == 0) return strict;
    double fallback = 0;
    for (int d = 0; d < 4; ++d)
        fallback += alike * window.pairs[d] +
                    counted * std::min(window.pairs[d], NFOR_NOISE_MIN_PAIRS - 1);
    best = RelaxedScan(window, divisor, fallback);
    fallback += 1 + (best ? 2 : 0);
    return std::max(strict, fallback);
}

// noise.comp, per invocation (pixel, channel z): NoisePixelFlops.
double NoiseFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::NforNoisePush>(d);
    double flops = 0;
    for (int x = 0; x < p.width; ++x)
        for (int y = 0; y < p.height; ++y) flops += NoisePixelFlops(NoiseWindowAt(x, y, p), p);
    return flops * d.timing.groups[2];
}

}  // namespace

const FormulaMap &NforFormulas() {
    static const FormulaMap formulas = {
        {"nfor_prefilter",
         {"per window step 6 (+ exp off the centre), per patch step 14, per pixel 3; every "
          "weight under the cut",
          PrefilterFlops, OpsBound::AtMost}},
        {"nfor_term",
         {"per offset with q inside, per channel 14 (15 min-variance) and 1; a pair with an "
          "end whose albedo is not trusted 6 more per channel, not counted",
          TermFlops, OpsBound::AtLeast}},
        {"nfor_noise",
         {"per direction and window pair inside 3 (+6 with a divisor), per direction with 3 "
          "pairs 1, per pixel 2 where one has them (+1 with a divisor); relaxed: the same "
          "pairs' alike tests (4), 2 counted per direction, then every pair off the centre 3 "
          "(+2), per direction with 2 pairs 1, whichever costs more; every divisor above the "
          "floor",
          NoiseFlops, OpsBound::AtMost}},
        {"nfor_box", {"an add per patch position inside", BoxFlops}},
        {"nfor_box_columns", {"an add per patch position inside and a divide", BoxFlops}},
        {"nfor_regress",
         {"per window step 3 + 4F + C(C+2) + 2C channels (+4 off the centre), per pixel the "
          "ridge, Cholesky and solves (C = F + 3); a second candidate of the pass its own "
          "sums and solves (+3 off the centre); no emitter or zero weight",
          RegressFlops, OpsBound::AtMost}},
        {"nfor_gather",
         {"per gather step 11 + 4F + 2C channels (+4 off the centre), per pixel a divide per "
          "channel; no emitter or zero weight",
          GatherFlops, OpsBound::AtMost}},
    };
    return formulas;
}

}  // namespace mcd::tool
