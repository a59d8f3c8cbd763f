#include "tools/mcdenoise/kernel_ops.h"

#include <cmath>
#include <cstring>
#include <functional>
#include <map>

#include "awr/shrink.h"
#include "bench/fma.h"
#include "host/kernels/bench_calibrate.h"
#include "rhf/distance.h"
#include "wavelet/lines.h"
#include "wavelet/swt.h"
#include "wavelet/swt_analyze.h"
#include "wavelet/tile.h"
#include "wavelet/wavelet.h"

namespace mcd::tool {
namespace {

// The push constants as the kernel's struct (zeros where the dispatch gave fewer bytes).
template <typename Push>
Push PushOf(const vk::KeptDispatch &d) {
    Push push{};
    std::memcpy(&push, d.push.data(), std::min(d.push.size(), sizeof(Push)));
    return push;
}

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

struct Formula {
    std::string rule;
    std::function<double(const vk::KeptDispatch &)> flops;
};

const std::map<std::string, Formula> &Formulas() {
    static const std::map<std::string, Formula> formulas = {
        {"bench_fma",
         {"iterations x 4 chains x 4 lanes x 2 (FMA) + 28 per invocation (shaders/bench/fma.h)",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::BenchFmaPush>(d);
              return BenchFmaFlops(p.count, p.iterations);
          }}},
        {"bench_stream", {"none: a copy", [](const vk::KeptDispatch &) { return 0.0; }}},
        // Per coefficient: sqrt, cs * sqrt, |w| - t, max, sign(w) * (...).
        {"awr_shrink",
         {"5 per coefficient of the grid (the kept low-low band counted too)",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::AwrShrinkPush>(d);
              return 5.0 * p.width * p.height * d.timing.groups[2];
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
         {"(2 (2w+1)^2 + 2) per centre and offset, border centres counted as interior ones",
          [](const vk::KeptDispatch &d) {
              auto p = PushOf<shader::RhfDistancePush>(d);
              double side = 2.0 * p.patchHalf + 1;
              return (2 * side * side + 2) * p.width * p.rows * d.timing.groups[2];
          }}},
    };
    return formulas;
}

}  // namespace

std::optional<double> KernelFlops(const vk::KeptDispatch &dispatch) {
    auto it = Formulas().find(dispatch.timing.kernel);
    if (it == Formulas().end()) return std::nullopt;
    return it->second.flops(dispatch);
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
    auto it = Formulas().find(kernel);
    return it == Formulas().end() ? "" : it->second.rule;
}

}  // namespace mcd::tool
