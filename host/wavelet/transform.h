// The multi-level (Mallat) 2D DWT on the GPU as a sequence of per-level dispatches:
// analysis, synthesis and the squared-filter variance analysis. Every level runs in
// place in the output image, through one interleaved temporary (rows padded to a multiple
// of 4 floats for the vec4 path), allocated on first use: a 0-level transform is a copy.
// The analysis runs as direct convolutions with the filter bank (analyze.comp, sharing
// convolve.glsl with the squared-filter kernel) and so does the synthesis
// (synthesize.glsl): on lavapipe about a quarter faster than the lifting wavefront, the
// same results up to round-off.
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

class WaveletTransform {
  public:
    WaveletTransform(vk::Context &context, int width, int height, int channels);

    // `in` and `coef` are width x height x channels; levels in [0, MaxWaveletLevels]. The
    // input and output of each transform may be the same image (in place).
    void RecordAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                        const vk::GpuImage &in, vk::GpuImage &coef);
    void RecordSynthesis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                         const vk::GpuImage &coef, vk::GpuImage &out);
    // Synthesis of AWR's soft-shrunk coefficients (eq. 11) without a pass of its own:
    // every detail coefficient w of `coef` is read as sign(w) max(0, |w| - cs sqrt(var)),
    // var from `variance` (same size, not `out`), the coarsest low-low band as it is.
    // `coef` itself is left unchanged unless it is `out`.
    void RecordShrinkSynthesis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                               const vk::GpuImage &coef, const vk::GpuImage &variance, float cs,
                               vk::GpuImage &out);
    // Per-coefficient variance from per-pixel variance (AWR eqs. 9-10).
    void RecordSqAnalysis(vk::Recorder &recorder, WaveletBasis basis, int levels,
                          const vk::GpuImage &variance, vk::GpuImage &coef, float lowSum,
                          float highSum);
    // One level of it: level `level` (0 = the full image) reads the low-low band that
    // level's input occupies in `from` and writes its bands to the same region of `to`,
    // leaving the rest of `to` alone. Chained from image to image, the top-left corners
    // keep every level's scale variances, which the in-place transform overwrites.
    void RecordSqAnalysisLevel(vk::Recorder &recorder, WaveletBasis basis, int level,
                               const vk::GpuImage &from, vk::GpuImage &to, float lowSum,
                               float highSum);

  private:
    void Check(int levels, const vk::GpuImage &a, const vk::GpuImage &b) const;
    vk::MutableImageView Temporary();
    static void CopyUnlessSame(vk::Recorder &recorder, const vk::GpuImage &from,
                               const vk::GpuImage &to);

    vk::Context &context;
    int width, height, channels;
    vk::Buffer temporary;
};

}  // namespace mcd
