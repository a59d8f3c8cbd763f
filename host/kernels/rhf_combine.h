// Record RHF's multi-scale recombination (shaders/rhf/combine.comp).
#pragma once

#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// Where `filtered` lies in its whole frame, at its scale: a tile's window (origin even)
// interpolates at the whole frame's positions. Sizes 0: the image is the whole frame.
struct RhfCombineWindow {
    int originX = 0, originY = 0, frameWidth = 0, frameHeight = 0;
};

// The kernel RecordRhfCombine records.
vk::KernelDesc RhfCombineKernel();

// out = filtered - U(low) + U(coarse); low and coarse are one size, half of filtered's
// (rounded up), all 3 channels.
void RecordRhfCombine(vk::Context &context, vk::Recorder &recorder,
                      const vk::GpuImage &filtered, const vk::GpuImage &low,
                      const vk::GpuImage &coarse, vk::GpuImage &out,
                      const RhfCombineWindow &window = {});

}  // namespace mcd
