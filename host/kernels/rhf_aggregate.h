// Record RHF's aggregation (shaders/rhf/aggregate.comp): the filtered image of one scale.
#pragma once

#include "host/vk/buffer.h"
#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// The kernel RecordRhfAggregate records with these half-windows.
vk::KernelDesc RhfAggregateKernel(int searchHalf, int patchHalf);

// color and out are 3-channel images of one size; mask is select's, for the whole image.
void RecordRhfAggregate(vk::Context &context, vk::Recorder &recorder, const vk::GpuImage &color,
                        const vk::Buffer &mask, int patchHalf, int searchHalf,
                        vk::GpuImage &out);

}  // namespace mcd
