// What the two line-lifting wavelet kernels (analyze, synthesize) share on the host: the
// checks on the temporary and the recording of one pass. Layout only; their arithmetic
// lives in their GLSL.
#pragma once

#include <initializer_list>
#include <string>

#include "host/vk/context.h"
#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"
#include "wavelet/lines.h"

namespace mcd {

// The temporary must not alias the source or destination, and its rows are padded to
// whole vec4s so the rows passes can always move vec4s through it.
void CheckWaveletTemporary(const vk::ImageView &tmp, const vk::ImageView &src,
                           const vk::ImageView &dst, int width, const char *kernel);

// Record one pass (WAVELET_AXIS_ROWS or _COLUMNS) of the kernel in `spirv` over the
// width x height x channels region, from `src` into `dst`. The rows pass moves vec4s
// when both views keep rows and planes 16-byte aligned. `extra` follows WaveletLinesPush
// in the push constants (WAVELET_LINES_EXTRA_PUSH in the kernel); `reads` are bound, read
// only, at the bindings after WAVELET_LINES_DST.
void RecordWaveletLinePass(vk::Context &context, vk::Recorder &recorder, const char *kernel,
                           const uint32_t *spirv, size_t spirvBytes, WaveletBasis basis,
                           int axis, int width, int height, int channels,
                           const vk::ImageView &src, const vk::ImageView &dst,
                           const std::string &label, std::initializer_list<float> extra = {},
                           std::initializer_list<const vk::Buffer *> reads = {},
                           std::initializer_list<std::pair<uint32_t, int32_t>> spec = {});

}  // namespace mcd
