// Record one pass of one level of the stationary wavelet transform
// (shaders/wavelet/swt_analyze.comp, swt_synthesize.comp; layout in shaders/wavelet/swt.h).
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"
#include "wavelet/swt.h"

namespace mcd {

// AnalyzeFused: Haar only, a whole level (both axes) in one pass, reading as the rows pass
// and writing as the columns pass; never in place.
enum class SwtPass {
    AnalyzeRows,
    AnalyzeColumns,
    AnalyzeFused,
    SynthesizeColumns,
    SynthesizeRows
};

// `push` says the level (step, flags) and where the pass reads and writes in `src` (read
// through its float texel view) and `dst`; `channels` workgroup layers. `squared` only
// for the analysis passes.
void RecordWaveletSwtPass(vk::Context &context, vk::Recorder &recorder, SwtPass pass,
                          WaveletBasis basis, bool squared, const shader::WaveletSwtPush &push,
                          int channels, const vk::Buffer &src, vk::Buffer &dst,
                          const std::string &label);

}  // namespace mcd
