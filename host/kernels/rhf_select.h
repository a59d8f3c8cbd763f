// Record RHF's patch selection (shaders/rhf/select.comp) for a strip of centres.
#pragma once

#include "host/vk/buffer.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"

namespace mcd {

// Mask words per centre for a search half-window b: one bit per offset.
int RhfMaskWords(int searchHalf);

// The kernel RecordRhfSelect records with this search half-window, with the pooled veto
// (poolBound > 0) or without.
vk::KernelDesc RhfSelectKernel(int searchHalf, bool pooled);

// dist holds the strip's (2b+1)^2 distance planes of rows x width; mask (whole image,
// RhfMaskWords planes of height x width) gets the strip's rows. `nearest` patches are always
// taken (k_NN + 1 with the patch itself, 0 for none), ties as the tool breaks them. With
// poolBound > 0, pool (height x width floats: the bright samples pooled over each pixel's
// patch box of half-width patchHalf, RhfBrightPool) leaves out candidates whose pool Q
// differs from the centre's P as rates over the boxes' pixel counts aQ, aP (cut at the
// image's edges): (P/aP - Q/aQ)^2 > poolBound (P/aP^2 + Q/aQ^2); with 0 it is bound but not
// read.
void RecordRhfSelect(vk::Context &context, vk::Recorder &recorder, int width, int height,
                     int searchHalf, int rowBase, int rows, int nearest, float threshold,
                     const vk::Buffer &dist, const vk::Buffer &pool, float poolBound,
                     int patchHalf, vk::Buffer &mask);

}  // namespace mcd
