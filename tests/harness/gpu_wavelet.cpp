#include "harness/gpu_wavelet.h"

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet/transform.h"

namespace mcd::test {

Image GpuAnalyze(vk::Context &ctx, const Image &in, WaveletBasis basis, int levels) {
    vk::GpuImage src(ctx, in.width, in.height, in.channels, "in");
    vk::GpuImage coef(ctx, in.width, in.height, in.channels, "coef");
    src.Upload(in);
    WaveletTransform transform(ctx, in.width, in.height, in.channels);
    vk::Recorder recorder(ctx);
    transform.RecordAnalysis(recorder, basis, levels, src, coef);
    recorder.Submit();
    return coef.Download();
}

Image GpuSynthesize(vk::Context &ctx, const Image &coefficients, WaveletBasis basis,
                    int levels) {
    vk::GpuImage coef(ctx, coefficients.width, coefficients.height, coefficients.channels,
                      "coef");
    vk::GpuImage out(ctx, coefficients.width, coefficients.height, coefficients.channels,
                     "out");
    coef.Upload(coefficients);
    WaveletTransform transform(ctx, coefficients.width, coefficients.height,
                               coefficients.channels);
    vk::Recorder recorder(ctx);
    transform.RecordSynthesis(recorder, basis, levels, coef, out);
    recorder.Submit();
    return out.Download();
}

Image GpuSqAnalyze(vk::Context &ctx, const Image &variance, WaveletBasis basis, int levels,
                   float lowSum, float highSum) {
    vk::GpuImage src(ctx, variance.width, variance.height, variance.channels, "variance");
    vk::GpuImage coef(ctx, variance.width, variance.height, variance.channels, "coefvar");
    src.Upload(variance);
    WaveletTransform transform(ctx, variance.width, variance.height, variance.channels);
    vk::Recorder recorder(ctx);
    transform.RecordSqAnalysis(recorder, basis, levels, src, coef, lowSum, highSum);
    recorder.Submit();
    return coef.Download();
}

}  // namespace mcd::test
