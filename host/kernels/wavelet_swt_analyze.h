// Record one pass of one level of the stationary wavelet analysis
// (shaders/wavelet/swt_analyze.comp; layout in swt_analyze.h and swt.h).
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"
#include "wavelet/swt_analyze.h"

namespace mcd {

// Fused: Haar only, a whole level (both axes) in one pass, reading as the rows pass and
// writing as the columns pass; never in place.
enum class SwtAnalyzePass { Rows, Columns, Fused };

// `push` says the level (step, flags) and where the pass reads and writes in `src` (read
// through its float texel view) and `dst`; `channels` workgroup layers. `squared` squares
// every tap (the variance analysis).
void RecordWaveletSwtAnalyze(vk::Context &context, vk::Recorder &recorder, SwtAnalyzePass pass,
                             WaveletBasis basis, bool squared,
                             const shader::WaveletSwtAnalyzePush &push, int channels,
                             const vk::Buffer &src, vk::Buffer &dst, const std::string &label);

}  // namespace mcd
