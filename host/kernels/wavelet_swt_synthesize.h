// Record one pass of one level of the stationary wavelet synthesis
// (shaders/wavelet/swt_synthesize.comp; layout in swt_synthesize.h and swt.h).
#pragma once

#include <string>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"
#include "wavelet/swt_synthesize.h"

namespace mcd {

// A level is undone columns first, then rows.
enum class SwtSynthesizePass { Columns, Rows };

// `push` says the level (step, flags) and where the pass reads and writes in `src` (read
// through its float texel view) and `dst`; `channels` workgroup layers.
void RecordWaveletSwtSynthesize(vk::Context &context, vk::Recorder &recorder,
                                SwtSynthesizePass pass, WaveletBasis basis,
                                const shader::WaveletSwtSynthesizePush &push, int channels,
                                const vk::Buffer &src, vk::Buffer &dst,
                                const std::string &label);

}  // namespace mcd
