#include "host/methods/wavelet_transform.h"

#include <fmt/format.h>

#include "host/error.h"
#include "host/kernels/wavelet_analyze.h"
#include "host/kernels/wavelet_sqanalyze.h"
#include "host/kernels/wavelet_synthesize.h"

namespace mcd {

WaveletTransform::WaveletTransform(vk::Context &context, int width, int height, int channels)
    : context(context), width(width), height(height), channels(channels) {}

void WaveletTransform::Check(int levels, const vk::GpuImage &a, const vk::GpuImage &b) const {
    int maxLevels = MaxWaveletLevels(width, height);
    if (levels < 0 || levels > maxLevels)
        throw Error(fmt::format("{} wavelet levels requested; a {}x{} image allows 0..{}",
                                levels, width, height, maxLevels));
    for (const vk::GpuImage *image : {&a, &b})
        if (image->width != width || image->height != height || image->channels != channels)
            throw Error(fmt::format("wavelet transform set up for {}x{}x{} got {}x{}x{} ('{}')",
                                    width, height, channels, image->width, image->height,
                                    image->channels, image->buffer.Name()));
}

// Compact view of the region of `level` in scratch buffer `index` (0 or 1).
vk::ImageView WaveletTransform::Scratch(int index, int level) {
    if (!scratch[index].Valid()) {
        VkDeviceSize floats =
            VkDeviceSize(LevelExtent(width, 1)) * LevelExtent(height, 1) * channels;
        scratch[index] = vk::Buffer(context, floats * sizeof(float),
                                    fmt::format("wavelet.scratch{}", index));
    }
    int w = LevelExtent(width, level), h = LevelExtent(height, level);
    return {&scratch[index], w, w * h};
}

void WaveletTransform::RecordAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                                      const vk::GpuImage &in, const vk::GpuImage &coef) {
    Check(levels, in, coef);
    if (levels == 0) {
        recorder.Copy(in.buffer, coef.buffer, in.buffer.Bytes());
        return;
    }
    vk::ImageView src = in.View();
    for (int level = 0; level < levels; ++level) {
        bool last = level == levels - 1;
        // The low-low band ping-pongs between the scratch buffers; the last goes in place.
        vk::ImageView low = last ? coef.View() : Scratch(level % 2, level + 1);
        RecordWaveletAnalyze(context, recorder, basis, LevelExtent(width, level),
                             LevelExtent(height, level), channels, src, coef.View(), low,
                             fmt::format("wavelet.analyze.L{}", level));
        src = low;
    }
}

void WaveletTransform::RecordSynthesis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                                       const vk::GpuImage &coef, const vk::GpuImage &out) {
    Check(levels, coef, out);
    if (levels == 0) {
        recorder.Copy(coef.buffer, out.buffer, coef.buffer.Bytes());
        return;
    }
    vk::ImageView low = coef.View();
    for (int level = levels - 1; level >= 0; --level) {
        vk::ImageView dst = level == 0 ? out.View() : Scratch(level % 2, level);
        RecordWaveletSynthesize(context, recorder, basis, LevelExtent(width, level),
                                LevelExtent(height, level), channels, low, coef.View(), dst,
                                fmt::format("wavelet.synthesize.L{}", level));
        low = dst;
    }
}

void WaveletTransform::RecordSqAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                                        const vk::GpuImage &variance, const vk::GpuImage &coef,
                                        float lowSum, float highSum) {
    Check(levels, variance, coef);
    if (levels == 0) {
        recorder.Copy(variance.buffer, coef.buffer, variance.buffer.Bytes());
        return;
    }
    vk::ImageView src = variance.View();
    for (int level = 0; level < levels; ++level) {
        bool last = level == levels - 1;
        vk::ImageView low = last ? coef.View() : Scratch(level % 2, level + 1);
        RecordWaveletSqAnalyze(context, recorder, basis, LevelExtent(width, level),
                               LevelExtent(height, level), channels, src, coef.View(), low,
                               lowSum, highSum, fmt::format("wavelet.sqanalyze.L{}", level));
        src = low;
    }
}

}  // namespace mcd
