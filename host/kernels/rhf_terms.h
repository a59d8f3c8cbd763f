// Record RHF's per-offset pixel terms (shaders/rhf/terms.comp) for a strip of rows.
#pragma once

#include <vector>

#include "host/vk/buffer.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// Histograms on the GPU, planar [plane][y][x]: planes 0..3n-1 are the bins, plane 3n the
// sample count; plane p lives in slots[p / planesPerSlot] (one buffer holds at most
// 128 MiB on lavapipe, so a big frame's histograms take several).
struct RhfHistogram {
    std::vector<vk::Buffer> slots;
    int width = 0, height = 0, planes = 0, planesPerSlot = 0;
    size_t PixelCount() const { return size_t(width) * size_t(height); }
};

// The kernel RecordRhfTerms records with this search half-window on histograms in `slots`
// buffers.
vk::KernelDesc RhfTermsKernel(int searchHalf, int slots);

// termSum / termCount get (b+1)(2b+1) planes (offsets with dy >= 0) of rows x width, for image
// rows rowBase..rowBase+rows-1; bins and counts are multiplied by histScale as they are read.
// brightVeto > 0 marks vetoed pixel pairs with count -1 (shaders/rhf/terms.h); the bound is
// in the scale's rescaled counts. blockMax holds RecordRhfBlockMax's maxima of these
// histograms with this histScale (rhf_blockmax.h); bins they show no pair counts are skipped.
void RecordRhfTerms(vk::Context &context, vk::Recorder &recorder, const RhfHistogram &hist,
                    int searchHalf, int rowBase, int rows, float histScale, float brightVeto,
                    const vk::Buffer &blockMax, vk::Buffer &termSum, vk::Buffer &termCount);

}  // namespace mcd
