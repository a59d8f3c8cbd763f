// What the line wavelet kernels (analyze, sqanalyze, synthesize, synthesize_shrink) share
// on the host: the checks on the temporary and the recording of one pass. Layout only;
// their arithmetic lives in their GLSL.
#pragma once

#include <initializer_list>
#include <string>
#include <type_traits>
#include <vector>

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

// One dispatch of a pass: its kernel variant (WAVELET_SPEC_PART), label suffix and groups.
struct WaveletLineDispatch {
    const vk::Kernel *kernel = nullptr;
    const char *suffix = "";
    uint32_t groupsX = 0, groupsY = 0, groupsZ = 0;
};

// One pass of a line kernel, all but its push constants' extra fields: the line part of
// the push constants, the bindings and its dispatches (the interior segments and the
// edge segments apart where the axis has interior ones, tile.h; else one of all).
struct WaveletLinePass {
    shader::WaveletLinesPush lines{};
    std::vector<vk::Binding> bindings;
    std::vector<WaveletLineDispatch> dispatches;
};

// Interior segments along an axis of length n (tile.h; the GLSL twin is in lifting.glsl).
int WaveletInteriorSegments(int n);

// The pass (WAVELET_AXIS_ROWS or _COLUMNS) of the kernel in `spirv`, whose push constants
// take pushBytes, over the width x height x channels region, from `src` into `dst`. The
// rows pass moves vec4s when both views keep rows and planes 16-byte aligned. `reads` are
// bound, read only, at the slots they name (after WAVELET_LINES_DST).
WaveletLinePass MakeWaveletLinePass(vk::Context &context, const char *kernel,
                                    const uint32_t *spirv, size_t spirvBytes,
                                    uint32_t pushBytes, WaveletBasis basis, int axis, int width,
                                    int height, int channels, const vk::ImageView &src,
                                    const vk::MutableImageView &dst,
                                    std::initializer_list<vk::Binding> reads,
                                    std::initializer_list<std::pair<uint32_t, int32_t>> spec);

// Record that pass. `push` is the kernel's push struct: WaveletLinesPush itself, or a
// struct whose `lines` member is (WAVELET_LINES_EXTRA_PUSH in the kernel); its line part
// is filled here.
template <typename Push = shader::WaveletLinesPush>
void RecordWaveletLinePass(vk::Context &context, vk::Recorder &recorder, const char *kernel,
                           const uint32_t *spirv, size_t spirvBytes, WaveletBasis basis,
                           int axis, int width, int height, int channels,
                           const vk::ImageView &src, const vk::MutableImageView &dst,
                           const std::string &label, Push push = {},
                           std::initializer_list<vk::Binding> reads = {},
                           std::initializer_list<std::pair<uint32_t, int32_t>> spec = {}) {
    WaveletLinePass pass =
        MakeWaveletLinePass(context, kernel, spirv, spirvBytes, uint32_t(sizeof(Push)), basis,
                            axis, width, height, channels, src, dst, reads, spec);
    if constexpr (std::is_same_v<Push, shader::WaveletLinesPush>)
        push = pass.lines;
    else
        push.lines = pass.lines;
    for (const WaveletLineDispatch &d : pass.dispatches)
        recorder.Dispatch(*d.kernel, label + d.suffix, pass.bindings, push, d.groupsX,
                          d.groupsY, d.groupsZ);
}

}  // namespace mcd
