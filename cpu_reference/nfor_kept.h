// nfor's kept pixels smoothed (host/methods/nfor_kept.h), the CPU reference: every weight
// from the definition, in double.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd::ref {

// A pixel the fits left: mask 1, input and output finite, |output - input| <= 1e-3
// |input| + 1e-6 in every channel (the same), some input channel above 1e-4, and a pixel
// within r of mask 1 not the same. Each such pixel of
// `output` becomes sum_q w_q o_q / sum_q w_q over q within r (clipped; mask 1, o_q finite
// in every channel; not another kept pixel), w_q = exp(-|q - p|^2 / (r^2 / 2) - sum_j (s_j
// (F_q,j - F_p,j))^2), o the output before any change. With weakAlbedo > 0, an emitter (mask 0)
// whose largest albedo channel is below it is smoothed too, its sum over j from albedoPlanes
// on, and counts among the q; other emitters do not. With keptPixels false only such
// emitters change (the kept pixels are still left out of every mean). With lineRatio > 0,
// a weak emitter p with, along (1,0), (0,1), (1,1) or (1,-1), on both sides at 1 or 2 steps
// (inside the image) a pixel whose positive parts' sum S (of o; 0 where a channel is not
// finite) is at least lineRatio S_p, multiplies each w_q by exp(-ln((S_q / n + 0.01) / (S_p
// / n + 0.01))^2 / (2 lineRange^2)), n the channel count.
void NforSmoothKept(const Image &input, const Image &features,
                    const std::vector<double> &featureWeights, const Image &mask, int r,
                    double weakAlbedo, const Image *albedo, int albedoPlanes, Image *output,
                    bool keptPixels = true, double lineRatio = 0, double lineRange = 0.5);

}  // namespace mcd::ref
