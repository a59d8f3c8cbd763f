// Record RHF's bin maxima per block of a row (shaders/rhf/blockmax.comp).
#pragma once

#include "host/kernels/rhf_terms.h"
#include "host/vk/kernel.h"

namespace mcd {

// Blocks per row of a width-pixel image.
int RhfBlocks(int width);

// The kernel RecordRhfBlockMax records.
vk::KernelDesc RhfBlockMaxKernel();

// blockMax gets 3n planes of height x RhfBlocks(width): per bin plane, row and block the
// largest bin times histScale among the block's pixels with a non-zero count (-FLT_MAX when
// none has one), as terms.comp reads the bins.
void RecordRhfBlockMax(vk::Context &context, vk::Recorder &recorder, const RhfHistogram &hist,
                       float histScale, vk::Buffer &blockMax);

}  // namespace mcd
