#include "host/wavelet/swt.h"

#include <fmt/format.h>

#include <algorithm>

#include "host/error.h"
#include "host/kernels/wavelet_swt_analyze.h"
#include "host/kernels/wavelet_swt_synthesize.h"
#include "host/vk/context.h"
#include "wavelet/swt.h"

namespace mcd {

size_t SwtCoefficientBytes(int width, int height, int channels, int levels) {
    return size_t(width) * height * channels * shader::SwtPlaneCount(levels) * sizeof(float);
}

namespace {

size_t SwtBindingLimit(vk::Context &context) {
    return size_t(context.BindingBytes());
}

}  // namespace

int SwtChannelsPerBinding(vk::Context &context, int width, int height, int levels) {
    return int(SwtBindingLimit(context) / SwtCoefficientBytes(width, height, 1, levels));
}

void CheckSwtFits(vk::Context &context, int width, int height, int channels, int levels,
                  const char *caller) {
    size_t bytes = SwtCoefficientBytes(width, height, channels, levels);
    size_t limit = SwtBindingLimit(context);
    if (bytes > limit)
        throw Error(
            fmt::format(
                "{}: the stationary wavelet coefficients of a {}x{}x{} image at {} levels are "
                "{} "
                "planes, {:.1f} MiB, over the {:.1f} MiB one buffer binding allows here; use "
                "fewer levels, a smaller image or the decimated DWT",
                caller, width, height, channels, levels,
                channels * shader::SwtPlaneCount(levels), bytes / 1048576.0, limit / 1048576.0),
            ErrorKind::OutOfMemory);
}

SwtTransform::SwtTransform(vk::Context &context, int width, int height, int channels,
                           int levels)
    : context(context), width(width), height(height), channels(channels), levels(levels) {
    if (width < 1 || height < 1 || channels < 1)
        throw Error(
            fmt::format("stationary wavelet: empty image {}x{}x{}", width, height, channels),
            ErrorKind::InvalidArgument);
    int maxLevels = MaxWaveletLevels(width, height);
    if (levels < 0 || levels > maxLevels)
        throw Error(fmt::format("{} wavelet levels requested; a {}x{} image allows 0..{}",
                                levels, width, height, maxLevels),
                    ErrorKind::InvalidArgument);
    CheckSwtFits(context, width, height, channels, levels, "stationary wavelet");
    if (levels > 0)
        temporary = vk::Buffer(context, size_t(width) * height * channels * 2 * sizeof(float),
                               "swt.temporary");
}

vk::GpuImage SwtTransform::MakeCoefficients(const char *name) const {
    return vk::GpuImage(context, width, height, channels * shader::SwtPlaneCount(levels), name);
}

void SwtTransform::Check(const vk::GpuImage &image, int planes, const char *what,
                         bool atLeast) const {
    if (image.width != width || image.height != height ||
        (atLeast ? image.channels < planes : image.channels != planes))
        throw Error(
            fmt::format("stationary wavelet set up for {}x{}x{} got {} {}x{}x{}", width, height,
                        planes, what, image.width, image.height, image.channels),
            ErrorKind::Internal);
}

void SwtTransform::RecordAnalysis(vk::Recorder &recorder, WaveletBasis basis,
                                  const vk::GpuImage &in, vk::GpuImage &coef, bool squared,
                                  int firstChannel) {
    int count = shader::SwtPlaneCount(levels), plane = width * height;
    Check(in, firstChannel + channels, "input", true);
    Check(coef, channels * count, "coefficients", true);
    if (levels == 0) {
        recorder.Copy(in.buffer, coef.buffer, VkDeviceSize(channels) * plane * sizeof(float),
                      VkDeviceSize(firstChannel) * plane * sizeof(float));
        return;
    }
    for (int level = 0; level < levels; ++level) {
        int flags = (shader::SwtTransformsAxis(width, level) ? WAVELET_SWT_TRANSFORM_X : 0) |
                    (shader::SwtTransformsAxis(height, level) ? WAVELET_SWT_TRANSFORM_Y : 0);
        // Level 0 reads the image, deeper levels the previous level's low plane.
        shader::WaveletSwtAnalyzePush rows{
            width, height, 1 << level, flags, firstChannel * plane, plane, 0, 0, 2 * plane, 0};
        if (level > 0) {
            rows.srcBase = shader::SwtLowPlane(levels) * plane;
            rows.srcChannel = count * plane;
        }
        if (basis == WaveletBasis::Haar) {
            // One pass, reading the level's input as the rows pass does and writing as the
            // columns pass. Never in place (invocations read their neighbours' inputs):
            // deeper levels first copy the low planes into the temporary.
            shader::WaveletSwtAnalyzePush fused = rows;
            if (level > 0) {
                for (int c = 0; c < channels; ++c)
                    recorder.Copy(coef.buffer, temporary, VkDeviceSize(plane) * sizeof(float),
                                  (VkDeviceSize(c) * count + shader::SwtLowPlane(levels)) *
                                      plane * sizeof(float),
                                  VkDeviceSize(c) * plane * sizeof(float));
                fused.srcBase = 0;
                fused.srcChannel = plane;
            }
            fused.dstBase = shader::SwtDetailPlane(level, 0) * plane;
            fused.dstChannel = count * plane;
            fused.dstLow = shader::SwtLowPlane(levels) * plane;
            RecordWaveletSwtAnalyze(context, recorder, SwtAnalyzePass::Fused, basis, squared,
                                    fused, channels, level == 0 ? in.buffer : temporary,
                                    coef.buffer, fmt::format("swt.analyze.L{}", level));
            continue;
        }
        RecordWaveletSwtAnalyze(context, recorder, SwtAnalyzePass::Rows, basis, squared, rows,
                                channels, level == 0 ? in.buffer : coef.buffer, temporary,
                                fmt::format("swt.analyze.L{}.rows", level));
        shader::WaveletSwtAnalyzePush columns{width,
                                              height,
                                              1 << level,
                                              flags,
                                              0,
                                              2 * plane,
                                              0,
                                              shader::SwtDetailPlane(level, 0) * plane,
                                              count * plane,
                                              shader::SwtLowPlane(levels) * plane};
        RecordWaveletSwtAnalyze(context, recorder, SwtAnalyzePass::Columns, basis, squared,
                                columns, channels, temporary, coef.buffer,
                                fmt::format("swt.analyze.L{}.columns", level));
    }
}

void SwtTransform::RecordSynthesis(vk::Recorder &recorder, WaveletBasis basis,
                                   vk::GpuImage &coef, vk::GpuImage &out, int firstChannel) {
    int count = shader::SwtPlaneCount(levels), plane = width * height;
    Check(coef, channels * count, "coefficients", true);
    Check(out, firstChannel + channels, "output", true);
    if (levels == 0) {
        recorder.Copy(coef.buffer, out.buffer, VkDeviceSize(channels) * plane * sizeof(float),
                      0, VkDeviceSize(firstChannel) * plane * sizeof(float));
        return;
    }
    for (int level = levels - 1; level >= 0; --level) {
        int flags = (shader::SwtTransformsAxis(width, level) ? WAVELET_SWT_TRANSFORM_X : 0) |
                    (shader::SwtTransformsAxis(height, level) ? WAVELET_SWT_TRANSFORM_Y : 0);
        shader::WaveletSwtSynthesizePush columns{width,
                                                 height,
                                                 1 << level,
                                                 flags,
                                                 shader::SwtDetailPlane(level, 0) * plane,
                                                 count * plane,
                                                 shader::SwtLowPlane(levels) * plane,
                                                 0,
                                                 2 * plane,
                                                 0};
        RecordWaveletSwtSynthesize(context, recorder, SwtSynthesizePass::Columns, basis,
                                   columns, channels, coef.buffer, temporary,
                                   fmt::format("swt.synthesize.L{}.columns", level));
        // Level 0 writes the image, deeper levels the next finer level's low plane.
        shader::WaveletSwtSynthesizePush rows{
            width, height, 1 << level, flags, 0, 2 * plane, 0, firstChannel * plane, plane, 0};
        if (level > 0) {
            rows.dstBase = shader::SwtLowPlane(levels) * plane;
            rows.dstChannel = count * plane;
        }
        RecordWaveletSwtSynthesize(context, recorder, SwtSynthesizePass::Rows, basis, rows,
                                   channels, temporary, level == 0 ? out.buffer : coef.buffer,
                                   fmt::format("swt.synthesize.L{}.rows", level));
    }
}

}  // namespace mcd
