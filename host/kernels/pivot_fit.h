// Record the pivot filter's fit stage (shaders/pivot/fit.comp): per centre and channel, the
// grown square and the planes of the square and its quadrants, into two buffers of 8
// planes per channel (planes in shaders/pivot/pivot.h).
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// The optional guides on the GPU: one buffer of PIVOT_GUIDE_STRIDE floats per pixel
// (PivotGuideBuffer); `normals` and `ids` say which parts the kernels use (the others are
// compiled out). No image: neither.
struct PivotGpuGuides {
    const vk::GpuImage *image = nullptr;
    bool normals = false, ids = false;
};

struct PivotFitSettings {
    int maxRadius = 30;
    float targetNoise = 0.02f, goodNoise = 100.f, disagreement = 0.1f, k = 0.3f,
          sigmaWeight = 0.f, edge = 0.f;
};

// How many centres' planes PivotFitBuffers::Radii copies at a time from mapped memory.
constexpr size_t kPivotRadiiBlock = size_t(1) << 15;

// The fits on the GPU: per channel two buffers of PIVOT_PLANES_PER_BUFFER planes of the
// frame's size (planes 0..7 and 8..15, a centre's 8 planes adjacent; shaders/pivot/pivot.h),
// each its own binding, so that one binding holds one channel's planes.
struct PivotFitBuffers {
    PivotFitBuffers(vk::Context &context, int width, int height, int channels,
                    const std::string &name);

    int Channels() const { return int(lo.size()); }
    // The fits in the reference's layout (PivotFitsOfBuffers), and back.
    Image Download() const;
    void Upload(const Image &fits);
    // Each centre's radius (plane PIVOT_PLANES - 1; -1: no fit), one plane per channel, read
    // kPivotRadiiBlock centres at a time.
    Image Radii() const;

    std::vector<vk::GpuImage> lo, hi;
};

// The kernel RecordPivotFit records with these guides and zsn of 1 or 2 vec4s a pixel.
vk::KernelDesc PivotFitKernel(bool normals, bool ids, int zsnTexels);

// `zsn`: per channel an image of 8 planes holding z, s, nu, level and noise of each pixel
// adjacent (PivotZsnOf), as the ratio stage writes them; of 4 (z, s, nu) only where
// settings.edge is 0. One dispatch per channel, with that channel's packed input and fit
// buffers bound.
void RecordPivotFit(vk::Context &context, vk::Recorder &recorder,
                    const std::vector<vk::GpuImage> &zsn, const PivotGpuGuides &guides,
                    const PivotFitSettings &settings, PivotFitBuffers &fits, int rowBase,
                    int rows);

// The fit's packed input from z, s, nu, level and noise (same shape; level and noise the edge
// test's, PivotRatio), one image per channel: float i * 8 + k of channel c's holds z, s,
// nu, level, noise (k = 0..4; 5..7 zero) of pixel i in channel c, two vec4 texels a pixel;
// without `edgeInputs` float i * 4 + k holds z, s, nu (k = 0..2; 3 zero), one texel a pixel
// (level and noise unread).
std::vector<Image> PivotZsnOf(const Image &z, const Image &s, const Image &nu,
                              const Image &level, const Image &noise, bool edgeInputs = true);

// The guide buffer (a pixel's guides in one vec4 texel: the normal normalised, zero where
// it is zero, and the label of its (object id, part id) pair, 1 + the pair's index among the
// frame's distinct pairs, negated where the normal is zero; shaders/pivot/pivot.h) from an
// image of PIVOT_GUIDE_PLANES planes: normal x, y, z, object id, part id.
Image PivotGuideBuffer(const Image &planes);

// The fits in the reference's layout (cpu_reference/pivot_filter.h: plane p of channel c at
// channel p * channels + c) from the fit buffers' contents, every channel's one after the
// other (8 x channels planes in each of `lo` and `hi`), and back.
Image PivotFitsOfBuffers(const Image &lo, const Image &hi, int channels);
void PivotBuffersOfFits(const Image &fits, int channels, Image *lo, Image *hi);

// Throw unless `fits` holds channels x 2 buffers of width x height x PIVOT_PLANES_PER_BUFFER.
void CheckPivotFitBuffers(const char *what, int width, int height, int channels,
                          const PivotFitBuffers &fits);

// Throw unless the guide buffer matches width x height x PIVOT_GUIDE_STRIDE when one is used.
void CheckPivotGuides(const char *what, int width, int height, const PivotGpuGuides &guides);

}  // namespace mcd
