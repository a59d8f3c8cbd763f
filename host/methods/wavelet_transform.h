// The multi-level (Mallat) 2D DWT on the GPU as a sequence of per-level dispatches:
// analysis, synthesis and the squared-filter variance analysis. Analysis and synthesis
// run every level in place in the output image, through one interleaved temporary (rows
// padded to a multiple of 4 floats for the vec4 path). The squared-filter analysis
// carries its low-low band between levels in two scratch buffers. All of them are
// allocated on first use, only by transforms that need them.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

class WaveletTransform {
  public:
    WaveletTransform(vk::Context &context, int width, int height, int channels);

    // `in` and `coef` are width x height x channels; levels in [0, MaxWaveletLevels].
    void RecordAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                        const vk::GpuImage &in, const vk::GpuImage &coef);
    void RecordSynthesis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                         const vk::GpuImage &coef, const vk::GpuImage &out);
    // Per-coefficient variance from per-pixel variance (AWR eqs. 9-10).
    void RecordSqAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                          const vk::GpuImage &variance, const vk::GpuImage &coef, float lowSum,
                          float highSum);

  private:
    void Check(int levels, const vk::GpuImage &a, const vk::GpuImage &b) const;
    vk::ImageView Temporary();
    vk::ImageView Scratch(int index, int level);

    vk::Context &context;
    int width, height, channels;
    vk::Buffer temporary;
    vk::Buffer scratch[2];
};

}  // namespace mcd
