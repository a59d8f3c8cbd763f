// Record RHF's patch distances (shaders/rhf/distance.comp) for a strip of centres.
#pragma once

#include "host/vk/buffer.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// The kernel RecordRhfDistance records with these half-windows.
vk::KernelDesc RhfDistanceKernel(int searchHalf, int patchHalf);

// The term buffers hold image rows termBase..termBase+termRows-1 (they must cover the
// strip's rows - patchHalf - searchHalf to + patchHalf, inside the image); dist gets (2b+1)^2
// planes of rows x width.
void RecordRhfDistance(vk::Context &context, vk::Recorder &recorder, int width, int height,
                       int patchHalf, int searchHalf, int termBase, int termRows, int rowBase,
                       int rows, const vk::Buffer &termSum, const vk::Buffer &termCount,
                       vk::Buffer &dist);

}  // namespace mcd
