// The multi-level stationary (undecimated) 2D wavelet transform on the GPU
// (shaders/wavelet/swt.h): analysis, synthesis and the squared-tap variance analysis, each
// level a rows pass into a two-plane temporary and a columns pass out of it.
#pragma once

#include <cstddef>

#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"
#include "host/wavelet.h"

namespace mcd {

class SwtTransform {
  public:
    // Throws mcd::Error (via CheckSwtFits) when the coefficients would not fit one binding.
    SwtTransform(vk::Context &context, int width, int height, int channels, int levels);

    // The coefficient image: width x height x channels (3 levels + 1) planes.
    vk::GpuImage MakeCoefficients(const char *name) const;

    // `in` is width x height with at least firstChannel + channels channels, of which
    // channels [firstChannel, firstChannel + channels) are transformed (a group of a larger
    // image); `coef` from MakeCoefficients (or one with more planes: the first are used).
    // `squared` squares every tap (per-coefficient variance from per-pixel variance of
    // independent pixels).
    void RecordAnalysis(vk::Recorder &recorder, WaveletBasis basis, const vk::GpuImage &in,
                        vk::GpuImage &coef, bool squared = false, int firstChannel = 0);
    // The inverse into channels [firstChannel, firstChannel + channels) of `out`; it
    // overwrites the low plane of `coef` at levels > 1.
    void RecordSynthesis(vk::Recorder &recorder, WaveletBasis basis, vk::GpuImage &coef,
                         vk::GpuImage &out, int firstChannel = 0);

    int Levels() const { return levels; }

  private:
    void Check(const vk::GpuImage &image, int planes, const char *what,
               bool atLeast = false) const;

    vk::Context &context;
    int width, height, channels, levels;
    vk::Buffer temporary;  // row-low and row-high planes per channel
};

// Bytes of the coefficients of a `levels`-level SWT of a width x height x channels image.
size_t SwtCoefficientBytes(int width, int height, int channels, int levels);

// Throw mcd::Error, naming the sizes, unless the coefficients fit one storage binding
// (maxStorageBufferRange) and one texel view (maxTexelBufferElements).
void CheckSwtFits(vk::Context &context, int width, int height, int channels, int levels,
                  const char *caller);

// How many channels' coefficients fit one binding (0: not even one channel's).
int SwtChannelsPerBinding(vk::Context &context, int width, int height, int levels);

}  // namespace mcd
