#include "tools/mcdenoise/kernel_ops.h"

#include <algorithm>
#include <cmath>

#include "awr/shrink.h"
#include "bayes/bayes.h"
#include "bayes/shrink.h"
#include "bayes/swt_shrink.h"
#include "bench/fma.h"
#include "host/kernels/bench_calibrate.h"
#include "pivot/fit.h"
#include "pivot/pivot.h"
#include "rhf/distance.h"
#include "rhf/terms.h"
#include "tools/mcdenoise/kernel_ops_formulas.h"
#include "wavelet/lines.h"
#include "wavelet/swt.h"
#include "wavelet/swt_analyze.h"
#include "wavelet/swt_synthesize.h"
#include "wavelet/tile.h"
#include "wavelet/wavelet.h"

namespace mcd::tool {

double WindowPairs(int n, int r) {
    double pairs = 0;
    for (int x = 0; x < n; ++x) pairs += std::min(x + r, n - 1) - std::max(x - r, 0) + 1;
    return pairs;
}

double PatchTriples(int n, int r, int f) {
    double triples = 0;
    for (int x = 0; x < n; ++x)
        for (int u = std::max(x - r, 0); u <= std::min(x + r, n - 1); ++u) {
            int lo = std::max(-f, -std::min(x, u)), hi = std::min(f, n - 1 - std::max(x, u));
            triples += std::max(0, hi - lo + 1);
        }
    return triples;
}

namespace {

// The even and odd positions a wavelet line pass filters along its axis, over every line
// and channel: the region's, or the part its segments cover (shaders/wavelet/tile.h;
// segments start at multiples of WAVELET_TILE, an even number).
std::pair<double, double> WaveletPositions(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::WaveletLinesPush>(d);
    bool rows = d.Spec(WAVELET_SPEC_AXIS, WAVELET_AXIS_ROWS) == WAVELET_AXIS_ROWS;
    int part = d.Spec(WAVELET_SPEC_PART, WAVELET_PART_ALL);
    int length = rows ? p.width : p.height, lines = rows ? p.height : p.width;
    int along = int(rows ? d.timing.groups[0] : d.timing.groups[1]);
    int segments = (length + WAVELET_TILE - 1) / WAVELET_TILE;
    double even = (length + 1) / 2, odd = length / 2;
    if (part == WAVELET_PART_INTERIOR) even = odd = along * WAVELET_TILE / 2;
    if (part == WAVELET_PART_EDGES) {
        int interior = segments - along;
        even -= interior * WAVELET_TILE / 2, odd -= interior * WAVELET_TILE / 2;
    }
    double planes = double(lines) * d.timing.groups[2];
    return {even * planes, odd * planes};
}

// A wavelet line pass: a multiply and an add per tap of the even and odd positions'
// filters (`analysis`: CDF 9/7 9 and 7 taps, LeGall 5/3 5 and 3; the synthesis the other
// way round; Haar one operand pair, an add and a multiply), plus `extra` per position.
double WaveletFlops(const vk::KeptDispatch &d, bool analysis, double extra) {
    int basis = d.Spec(WAVELET_SPEC_BASIS, MCD_WAVELET_CDF97);
    double evenTaps = 1, oddTaps = 1;
    if (basis == MCD_WAVELET_CDF97) evenTaps = analysis ? 9 : 7, oddTaps = analysis ? 7 : 9;
    if (basis == MCD_WAVELET_LEGALL53) evenTaps = analysis ? 5 : 3, oddTaps = analysis ? 3 : 5;
    auto [even, odd] = WaveletPositions(d);
    return even * (2 * evenTaps + extra) + odd * (2 * oddTaps + extra);
}

// swt_analyze.comp's Analyze at one position of an axis it transforms: a multiply-add per
// tap of both filters (CDF 9/7: 9 + 7, LeGall 5/3: 5 + 3); Haar two products and a sum per
// band (6), squared one pair for both (3).
double SwtAnalyzeFlops(int basis, bool squared) {
    if (basis == MCD_WAVELET_HAAR) return squared ? 3 : 6;
    return basis == MCD_WAVELET_CDF97 ? 2 * (9 + 7) : 2 * (5 + 3);
}

// swt_analyze.comp: per position of every channel the rows pass analyses one line, the
// columns pass two (the row-low and row-high planes), the fused Haar pass four pairs (two
// per axis); an axis not transformed at this level copies.
double SwtAnalyzePassFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::WaveletSwtAnalyzePush>(d);
    int basis = d.Spec(WAVELET_SWT_SPEC_BASIS, MCD_WAVELET_CDF97);
    int axis = d.Spec(WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS);
    bool squared = d.Spec(WAVELET_SWT_ANALYZE_SPEC_SQUARED, 0) != 0;
    bool tx = p.flags & WAVELET_SWT_TRANSFORM_X, ty = p.flags & WAVELET_SWT_TRANSFORM_Y;
    double each = SwtAnalyzeFlops(basis, squared), perPosition = 0;
    if (axis == WAVELET_SWT_ROWS) perPosition = tx ? each : 0;
    if (axis == WAVELET_SWT_COLUMNS) perPosition = ty ? 2 * each : 0;
    if (axis == WAVELET_SWT_FUSED) perPosition = (tx ? 2 * each : 0) + (ty ? 2 * each : 0);
    return perPosition * p.width * p.height * d.timing.groups[2];
}

// swt_synthesize.comp's Synthesize summed along a line of n it transforms: a multiply-add
// per tap of both filters and the half (CDF 9/7: 2 (7 + 9) + 1, LeGall 2 (3 + 5) + 1);
// Haar the first pair (3) everywhere, the second, the sum and the half (5) from i = step.
double SwtSynthesizeLineFlops(int basis, int n, int step) {
    if (basis == MCD_WAVELET_HAAR) return 3.0 * n + 5.0 * std::max(0, n - step);
    return (basis == MCD_WAVELET_CDF97 ? 33.0 : 17.0) * n;
}

// swt_synthesize.comp: the rows pass synthesises one line per row and channel, the columns
// pass two per column (row-low and row-high).
double SwtSynthesizePassFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::WaveletSwtSynthesizePush>(d);
    int basis = d.Spec(WAVELET_SWT_SPEC_BASIS, MCD_WAVELET_CDF97);
    bool rows = d.Spec(WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS) == WAVELET_SWT_ROWS;
    bool transform = p.flags & (rows ? WAVELET_SWT_TRANSFORM_X : WAVELET_SWT_TRANSFORM_Y);
    if (!transform) return 0;
    double lines = rows ? double(p.height) : 2.0 * p.width;
    return lines * d.timing.groups[2] *
           SwtSynthesizeLineFlops(basis, rows ? p.width : p.height, p.step);
}

// bayes's Shrink of one coefficient, on its costlier path: |v| / b, asinh, / du (3), then
// past the table's end sinh, two products, a difference and the sum (5; inside it the
// interpolation's fraction and mix take 4).
constexpr double kBayesShrinkFlops = 8;

// rhf/distance.comp's CentreDistance at centre (x, y) and offset (ox, oy): nothing where
// the candidate's patch, shrunk to w0 at the border, leaves the frame; else a sum and a count
// per position of the (2 w0 + 1)^2 patch and the divide's 2 (no pair vetoed).
double RhfCentreFlops(int x, int y, int ox, int oy, int pw, int w, int h) {
    int w0 = std::min(std::min(pw, std::min(x, y)), std::min(w - 1 - x, h - 1 - y));
    int qx = x + ox, qy = y + oy;
    if (qx < w0 || qx > w - 1 - w0 || qy < w0 || qy > h - 1 - w0) return 0;
    double side = 2.0 * w0 + 1;
    return 2 * side * side + 2;
}

// distance.comp's lane at x0 in a row whose centres and candidates have whole patches: the
// PIX centres' sums (2 per patch position, centres past the frame too), the divide (2) of
// each centre at least w from the sides whose candidate is too, and CentreDistance for
// the centres within w of a side (`y` any such row: the same there).
double RhfInsideLaneFlops(int x0, int ox, int oy, int y, int pw, int w, int h) {
    const int pix = RHF_DISTANCE_PIXELS_PER_LANE;
    double side = 2.0 * pw + 1, flops = pix * side * side * 2;
    for (int j = 0; j < pix; ++j) {
        int x = x0 + j, qx = x + ox;
        if (x >= pw && x <= w - 1 - pw && qx >= pw && qx <= w - 1 - pw) flops += 2;
    }
    int left = std::clamp(pw - x0, 0, pix), end = std::min(pix, w - x0);
    int right = std::max(std::clamp(w - pw - x0, 0, pix), left);
    for (int j = 0; j < pix; ++j)
        if (j < left || (j >= right && j < end))
            flops += RhfCentreFlops(x0 + j, y, ox, oy, pw, w, h);
    return flops;
}

// rhf/distance.comp per offset (grid layer): its rows with whole patches lane by lane, the
// others centre by centre (CentreDistance).
double RhfDistanceFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::RhfDistancePush>(d);
    const int pix = RHF_DISTANCE_PIXELS_PER_LANE;
    int b = d.Spec(RHF_DISTANCE_SPEC_SEARCH_HALF, 6),
        pw = d.Spec(RHF_DISTANCE_SPEC_PATCH_HALF, 1);
    int w = p.width, h = p.height, side = 2 * b + 1;
    double flops = 0;
    for (uint32_t o = 0; o < d.timing.groups[2]; ++o) {
        int ox = int(o) % side - b, oy = int(o) / side - b;
        double lanes = -1;  // one inside row's lanes, the same in every inside row
        for (uint32_t r = 0; r < d.timing.groups[1]; ++r) {
            int y = p.rowBase + int(r), qy = y + oy;
            if (y >= pw && y <= h - 1 - pw && qy >= pw && qy <= h - 1 - pw) {
                if (lanes < 0) {
                    lanes = 0;
                    for (int x0 = 0; x0 < w; x0 += pix)
                        lanes += RhfInsideLaneFlops(x0, ox, oy, y, pw, w, h);
                }
                flops += lanes;
                continue;
            }
            for (int x = 0; x < w; ++x) flops += RhfCentreFlops(x, y, ox, oy, pw, w, h);
        }
    }
    return flops;
}

// rhf/terms.comp per lane (PIX pixels of a row, window row dy) whose candidate row is
// inside: the counts' scaling (a multiply per pixel and candidate inside); per bin plane
// MayCount's 2 QB + 1 maxima and sum, a multiply per in-frame bin loaded (Bin), and
// AddTerms's sum per pair (1) and, for pairs with both ends in the frame, 9 more; with the
// veto, the harmonic mean and its scale per pair (5).
double RhfTermsFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::RhfTermsPush>(d);
    const int pix = RHF_TERMS_PIXELS_PER_LANE, b = d.Spec(RHF_TERMS_SPEC_SEARCH_HALF, 6);
    const int side = 2 * b + 1, qb = (b + pix - 1) / pix;
    double flops = 0;
    for (int x0 = 0; x0 < p.width; x0 += pix) {
        int validP = std::min(pix, p.width - x0);
        int validQ = std::min(x0 + pix - 1 + b, p.width - 1) - std::max(x0 - b, 0) + 1;
        double pairs = 0;
        for (int j = 0; j < validP; ++j)
            pairs += std::min(x0 + j + b, p.width - 1) - std::max(x0 + j - b, 0) + 1;
        double perPlane = 2 * qb + 2 + validP + validQ + pix * side + 9 * pairs;
        double lane = validP + validQ + p.binPlanes * perPlane;
        if (p.brightVeto > 0) lane += 5.0 * pix * side;
        for (uint32_t r = 0; r < d.timing.groups[1]; ++r)
            for (uint32_t dy = 0; dy < d.timing.groups[2]; ++dy) {
                int qy = p.rowBase + int(r) + int(dy);
                if (qy >= 0 && qy < p.height) flops += lane;
            }
    }
    return flops;
}

// pivot/lattice.glsl's latticeStep.
int PivotLatticeStep(double radius) {
    int step = 1;
    while (step < PIVOT_LATTICE_MAX_STEP && 2.0 * step <= radius / 2.0) step *= 2;
    return step;
}

// The radius pivot/fit.comp's growth reaches at most at centre (x0, y0): from 2 until the
// square covers the frame, reaches maxRadius, or the next radius leaves the centre's
// lattice (the data may stop it sooner: a quiet fit, a disagreeing quadrant).
int PivotGrowthBound(int x0, int y0, int w, int h, int maxRadius) {
    for (int r = 2;; ++r) {
        bool covers = x0 - r <= 0 && y0 - r <= 0 && x0 + r >= w - 1 && y0 + r >= h - 1;
        int step = PivotLatticeStep(r + 1);
        if (covers || r >= maxRadius || x0 % step != 0 || y0 % step != 0) return r;
    }
}

// pivot/fit.comp per centre (invocation), bounded: growth to PivotGrowthBound's radius R
// and a final fit at R for every centre (one that leaves its lattice stores its growth
// fits instead, fewer; one that disagrees fits a smaller square). Per pixel of a growth
// ring weightAt (the geometric term 1, +8 with normals; the exponent 6; exp and the
// product 2) and addSample with the mean's sum (21); the final fit's weightAt adds the
// distance term (6). Moments sum in 10 adds; a solve takes 39; from r = 2 each ring solves
// the square (8 sums) and the 4 quadrants (3 sums each, and the disagreement test's 5) and
// tests the noise (2). The 3x3 mean (an add per pixel inside and a divide), the growth
// rings' sums into the parts (1 + 12 per ring), <z> (1); the final fit's parts (3 sums
// per row off the centre's), its square's solve and storeFits (4 quadrants summed and
// solved).
double PivotFitFlops(const vk::KeptDispatch &d) {
    auto p = PushOf<shader::PivotFitPush>(d);
    const double sum = 10, solve = 39;
    double geometric = 1 + (d.Spec(PIVOT_SPEC_NORMALS, 0) != 0 ? 8 : 0);
    double growthPixel = geometric + 6 + 2 + 21, finalPixel = growthPixel + 6;
    double ring = 8 * sum + solve + 4 * (3 * sum + solve + 5) + 2;
    double store = 4 * (3 * sum + solve);
    auto inFrame = [&](int at, int r, int n) {
        return std::min(at + r, n - 1) - std::max(at - r, 0) + 1;
    };
    double flops = 0;
    for (uint32_t row = 0; row < d.timing.groups[1]; ++row) {
        int y0 = p.rowBase + int(row);
        for (int x0 = 0; x0 < p.width; ++x0) {
            int r = PivotGrowthBound(x0, y0, p.width, p.height, p.maxRadius);
            int rows = inFrame(y0, r, p.height);
            double square = double(inFrame(x0, r, p.width)) * rows;
            double mean = double(inFrame(x0, 1, p.width)) * inFrame(y0, 1, p.height) + 1;
            double growth = square * growthPixel + sum * (1 + 12 * r) + (r - 1) * ring + 1;
            double fit = square * finalPixel + 3 * sum * (rows - 1) + 8 * sum + solve + store;
            flops += mean + growth + fit;
        }
    }
    return flops * d.timing.groups[2];
}

const FormulaMap &Formulas() {
    static const FormulaMap formulas = {
        {"bench_fma",
         {"iterations x 4 chains x 4 lanes x 2 (FMA) + 28 per invocation (shaders/bench/fma.h)",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::BenchFmaPush>(d);
              return BenchFmaFlops(p.count, p.iterations);
          }}},
        {"bench_stream", {"none: a copy", [](const vk::KeptDispatch &) { return 0.0; }}},
        // Per coefficient: sqrt, cs * sqrt, |w| - t, max, sign(w) * (...).
        {"awr_shrink",
         {"5 per coefficient outside the kept low-low band",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::AwrShrinkPush>(d);
              double kept =
                  double(std::min(p.lowWidth, p.width)) * std::min(p.lowHeight, p.height);
              return 5.0 * (double(p.width) * p.height - kept) * d.timing.groups[2];
          }}},
        {"wavelet_analyze",
         {"per filtered position a multiply and an add per tap (CDF 9/7: 18 even, 14 odd; "
          "LeGall 5/3: 10, 6; Haar: 2)",
          [](const vk::KeptDispatch &d) { return WaveletFlops(d, true, 0); }}},
        {"wavelet_sqanalyze",
         {"as wavelet_analyze, plus the renormalising multiply per position",
          [](const vk::KeptDispatch &d) { return WaveletFlops(d, true, 1); }}},
        {"wavelet_synthesize",
         {"per position a multiply and an add per tap of the inverse filters (CDF 9/7: 14 "
          "even, 18 odd; LeGall: 6, 10; Haar: 2)",
          [](const vk::KeptDispatch &d) { return WaveletFlops(d, false, 0); }}},
        // The columns pass thresholds the three detail bands' coefficients as it loads them.
        {"wavelet_synthesize_shrink",
         {"as wavelet_synthesize, plus 5 per detail coefficient (3/4 of the positions)",
          [](const vk::KeptDispatch &d) { return WaveletFlops(d, false, 5 * 0.75); }}},
        // Per (centre, offset): the patch's (2w + 1)^2 term pairs each add to the sum and
        // the count, then count + 1e-4 and one divide; every output as an interior one.
        {"rhf_distance",
         {"per lane of a whole-patch row 2 (2w+1)^2 per centre and 2 per divide, border "
          "centres' shrunk patches 2 (2w0+1)^2 + 2; no pair vetoed",
          RhfDistanceFlops, OpsBound::AtMost}},
        {"rhf_terms",
         {"per lane and bin plane 2QB + 2 + the bins' scaling + 10 per in-frame pair (1 "
          "outside); every plane marked, every pair counted",
          RhfTermsFlops, OpsBound::AtMost}},
        {"wavelet_swt_analyze",
         {"per position and line analysed: CDF 9/7 32, LeGall 16, Haar 6 (squared 3); "
          "columns two lines, fused Haar four pairs",
          SwtAnalyzePassFlops}},
        {"wavelet_swt_synthesize",
         {"per position and line synthesised: CDF 9/7 33, LeGall 17, Haar 3 (+5 from "
          "i = step); columns two lines",
          SwtSynthesizePassFlops}},
        {"pivot_fit",
         {"per centre growth to the lattice's or maxRadius's radius R (ring pixels 30, "
          "+8 with normals; 417 per ring from 2) and a final fit at R (pixels 36, +8; 395, 30 "
          "per row)",
          PivotFitFlops, OpsBound::AtMost}},
        {"bayes_shrink",
         {"8 per detail coefficient (the costlier path, past the table's end); every band "
          "shrunk",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::BayesShrinkPush>(d);
              int lowW = p.width, lowH = p.height;
              for (int k = 0; k < p.levels; ++k) lowW = (lowW + 1) / 2, lowH = (lowH + 1) / 2;
              double details = double(p.width) * p.height - double(lowW) * lowH;
              return kBayesShrinkFlops * details * d.timing.groups[2];
          },
          OpsBound::AtMost}},
        {"bayes_swt_shrink",
         {"8 per coefficient of each detail band (the costlier path); every band shrunk",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::BayesSwtShrinkPush>(d);
              return kBayesShrinkFlops * p.width * p.height * d.timing.groups[2];
          },
          OpsBound::AtMost}},
    };
    return formulas;
}

const Formula *Find(const std::string &kernel) {
    auto it = Formulas().find(kernel);
    if (it != Formulas().end()) return &it->second;
    auto nfor = NforFormulas().find(kernel);
    return nfor == NforFormulas().end() ? nullptr : &nfor->second;
}

}  // namespace

std::optional<double> KernelFlops(const vk::KeptDispatch &dispatch) {
    const Formula *formula = Find(dispatch.timing.kernel);
    if (!formula) return std::nullopt;
    return formula->flops(dispatch);
}

std::optional<double> KernelTouchedBytes(const vk::KeptDispatch &dispatch) {
    const std::string &kernel = dispatch.timing.kernel;
    // The SWT's passes read and write whole planes of the level's (3 levels + 1)-plane
    // coefficients per channel: analysis rows 1 in, 2 out; columns 2 in, 4 out; both axes at
    // once (Haar) 1 in, 4 out; synthesis columns 4 in, 2 out; rows 2 in, 1 out. The two
    // kernels' push constants begin alike (width, height).
    if (kernel == "wavelet_swt_analyze" || kernel == "wavelet_swt_synthesize") {
        auto p = PushOf<shader::WaveletSwtAnalyzePush>(dispatch);
        int axis = dispatch.Spec(WAVELET_SWT_SPEC_AXIS, WAVELET_SWT_ROWS);
        double planes = axis == WAVELET_SWT_ROWS ? 3 : axis == WAVELET_SWT_COLUMNS ? 6 : 5;
        return planes * 4 * p.width * p.height * dispatch.timing.groups[2];
    }
    int arrays = kernel == "wavelet_synthesize_shrink" ? 3 : 2;
    if (kernel != "wavelet_analyze" && kernel != "wavelet_sqanalyze" &&
        kernel != "wavelet_synthesize" && kernel != "wavelet_synthesize_shrink")
        return std::nullopt;
    auto [even, odd] = WaveletPositions(dispatch);
    return (even + odd) * 4 * arrays;
}

std::string KernelFlopsRule(const std::string &kernel) {
    const Formula *formula = Find(kernel);
    return formula ? formula->rule : "";
}

OpsBound KernelFlopsBound(const std::string &kernel) {
    const Formula *formula = Find(kernel);
    return formula ? formula->bound : OpsBound::Exact;
}

}  // namespace mcd::tool
