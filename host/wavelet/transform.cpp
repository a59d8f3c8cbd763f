#include "host/wavelet/transform.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/kernels/wavelet_analyze.h"
#include "host/kernels/wavelet_sqanalyze.h"
#include "host/kernels/wavelet_synthesize.h"
#include "host/kernels/wavelet_synthesize_shrink.h"

namespace mcd {

WaveletTransform::WaveletTransform(vk::Context &context, int width, int height, int channels)
    : context(context), width(width), height(height), channels(channels) {}

void WaveletTransform::Check(int levels, const vk::GpuImage &a, const vk::GpuImage &b) const {
    int maxLevels = MaxWaveletLevels(width, height);
    if (levels < 0 || levels > maxLevels)
        throw Error(fmt::format("{} wavelet levels requested; a {}x{} image allows 0..{}",
                                levels, width, height, maxLevels),
                    ErrorKind::InvalidArgument);
    for (const vk::GpuImage *image : {&a, &b})
        if (image->width != width || image->height != height || image->channels != channels)
            throw Error(fmt::format("wavelet transform set up for {}x{}x{} got {}x{}x{} ('{}')",
                                    width, height, channels, image->width, image->height,
                                    image->channels, image->buffer.Name()),
                        ErrorKind::Internal);
}

// A copy of a buffer onto itself is invalid in Vulkan, and in place is what it asks for.
void WaveletTransform::CopyUnlessSame(vk::Recorder &recorder, const vk::GpuImage &from,
                                      const vk::GpuImage &to) {
    if (&from.buffer != &to.buffer) recorder.Copy(from.buffer, to.buffer, from.buffer.Bytes());
}

// The interleaved temporary between the two passes of a level, rows padded to 4 floats.
vk::MutableImageView WaveletTransform::Temporary() {
    int stride = (width + 3) / 4 * 4;
    if (!temporary.Valid())
        temporary =
            vk::Buffer(context, VkDeviceSize(stride) * height * channels * sizeof(float),
                       "wavelet.temporary");
    return {&temporary, stride, stride * height};
}

void WaveletTransform::RecordAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                                      const vk::GpuImage &in, vk::GpuImage &coef) {
    Check(levels, in, coef);
    if (levels == 0) {
        CopyUnlessSame(recorder, in, coef);
        return;
    }
    // Level 0 reads the image; deeper levels transform their low-low band in place.
    for (int level = 0; level < levels; ++level)
        RecordWaveletAnalyze(context, recorder, basis, LevelExtent(width, level),
                             LevelExtent(height, level), channels,
                             level == 0 ? in.View() : coef.View(), Temporary(),
                             coef.MutableView(), fmt::format("wavelet.analyze.L{}", level));
}

void WaveletTransform::RecordSynthesis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                                       const vk::GpuImage &coef, vk::GpuImage &out) {
    Check(levels, coef, out);
    // Work in place in `out` so the caller's coefficients survive (unless they are `out`).
    CopyUnlessSame(recorder, coef, out);
    for (int level = levels - 1; level >= 0; --level)
        RecordWaveletSynthesize(context, recorder, basis, LevelExtent(width, level),
                                LevelExtent(height, level), channels, out.View(), Temporary(),
                                out.MutableView(),
                                fmt::format("wavelet.synthesize.L{}", level));
}

void WaveletTransform::RecordShrinkSynthesis(vk::Recorder &recorder, WaveletBasis basis,
                                             int levels, const vk::GpuImage &coef,
                                             const vk::GpuImage &variance, float cs,
                                             vk::GpuImage &out) {
    Check(levels, coef, out);
    Check(levels, variance, out);
    if (&variance.buffer == &out.buffer)
        throw Error("shrink synthesis: the variances must not be the output image",
                    ErrorKind::Internal);
    // In place in `out`, as RecordSynthesis (with 0 levels nothing is a detail).
    CopyUnlessSame(recorder, coef, out);
    for (int level = levels - 1; level >= 0; --level)
        RecordWaveletSynthesizeShrink(context, recorder, basis, LevelExtent(width, level),
                                      LevelExtent(height, level), channels, out.View(),
                                      variance.View(), cs, Temporary(), out.MutableView(),
                                      fmt::format("wavelet.synthesize_shrink.L{}", level));
}

void WaveletTransform::RecordSqAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                                        const vk::GpuImage &variance, vk::GpuImage &coef,
                                        float lowSum, float highSum) {
    Check(levels, variance, coef);
    if (levels == 0) {
        CopyUnlessSame(recorder, variance, coef);
        return;
    }
    for (int level = 0; level < levels; ++level)
        RecordWaveletSqAnalyze(
            context, recorder, basis, LevelExtent(width, level), LevelExtent(height, level),
            channels, level == 0 ? variance.View() : coef.View(), Temporary(),
            coef.MutableView(), lowSum, highSum, fmt::format("wavelet.sqanalyze.L{}", level));
}

void WaveletTransform::RecordSqAnalysisLevel(vk::Recorder &recorder, WaveletBasis basis,
                                             int level, const vk::GpuImage &from,
                                             vk::GpuImage &to, float lowSum, float highSum) {
    Check(level + 1, from, to);
    RecordWaveletSqAnalyze(context, recorder, basis, LevelExtent(width, level),
                           LevelExtent(height, level), channels, from.View(), Temporary(),
                           to.MutableView(), lowSum, highSum,
                           fmt::format("wavelet.sqanalyze.L{}", level));
}

}  // namespace mcd
