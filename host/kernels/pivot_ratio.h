// Record the pivot filter's ratio stage (shaders/pivot/ratio.comp): z = L / L_a, the
// variance s of z and its relative version nu (-1 where the pivot is at or below the
// channel's threshold, or on an object/part boundary when `guides` has ids).
#pragma once

#include <vector>

#include "host/kernels/pivot_fit.h"
#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// The kernel RecordPivotRatio records: with a variance layer or without, with the ids'
// guide or without, zsn of 1 or 2 vec4s a pixel.
vk::KernelDesc PivotRatioKernel(bool variance, bool ids, int zsnTexels);

// `color`, `pivot`, `variance` (nullptr: estimate the noise from the 3x3 neighbours), `z`,
// `s`, `nu`: same size, 1 to 4 channels; `thresholds` one per channel. `zsn`, one image per
// channel, receives the same z, s, nu packed for the fit and the gather (PivotZsnOf): with 8
// planes also the 3x3 median of z and the 3x3 mean of s (the shading-edge test's inputs),
// with 4 planes not (a run without the test). `unusedSlot`, at most kPivotUnusedSlotBytes,
// fills the packed slots of the channels the frame lacks, which the kernel does not touch:
// their traffic counts next to nothing.
void RecordPivotRatio(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                      const vk::GpuImage &pivot, const vk::GpuImage *variance,
                      const std::vector<float> &thresholds, const PivotGpuGuides &guides,
                      vk::GpuImage &z, vk::GpuImage &s, vk::GpuImage &nu,
                      std::vector<vk::GpuImage> &zsn, const vk::Buffer &unusedSlot);

// The size of RecordPivotRatio's unusedSlot: one vec4.
constexpr size_t kPivotUnusedSlotBytes = 16;

// Throw unless the images have the same width, height and channel count.
void CheckPivotShapes(const char *what, const vk::GpuImage &a,
                      std::initializer_list<const vk::GpuImage *> others);

// Throw unless `zsn` holds an image of `a`'s size for each of its channels, all of
// PIVOT_ZSN_EDGE_PLANES planes (z, s, nu, level, noise per pixel) or all of PIVOT_ZSN_PLANES
// (z, s, nu); return the vec4 texels a pixel (2 or 1).
int CheckPivotZsn(const char *what, const vk::GpuImage &a,
                  const std::vector<vk::GpuImage> &zsn);
// The same for a width x height image of `channels` channels.
int CheckPivotZsn(const char *what, int width, int height, int channels,
                  const std::vector<vk::GpuImage> &zsn);

// Refuse the shading-edge test (`edge` > 0) on packed inputs of one texel a pixel, which lack
// its level and noise.
void CheckPivotZsnHoldsEdge(const char *what, int zsnTexels, float edge);

}  // namespace mcd
