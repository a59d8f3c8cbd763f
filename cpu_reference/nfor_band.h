// nfor's glint bands (host/methods/nfor_band.h), the CPU reference, in double.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// A pixel moves where a pixel of `albedo` with a channel above glintAlbedo lies within `reach`
// (Chebyshev), none of its channels is above emitterAlbedo, its `alpha` (where given) is above
// 0 and its values are finite; such a pixel (an emitter or empty) also flags the samples. With
// l = log(max(Y, 0) + 0.01) of the output's luminance Y (Rec. 709; channel 0 alone under 3
// channels), g its central differences (one-sided at the frame's edges), J = G * (g g^T) for G
// the 2-D Gaussian of tensorSigma over -(int(3 tensorSigma) + 1)..that, normalised, the frame's
// edges repeated: eigenvalues l1 >= l2, the line t perpendicular to l1's vector (J_xy, l1 -
// J_xx), coherence
// ((l1 - l2) / (l1 + l2))^2. Over k in -radius..radius, the output and the emitter flags
// sampled bilinearly at p + k t (held inside the frame), weight exp(-k^2 / 2 sigma^2) x (1 -
// the flags' value), a sample with a non-finite value left out, each scaled so that its
// luminance lies within [Y / bound, Y bound + 0.01] (one of luminance <= 0 black); the pixel
// becomes out + coherence (mean - out). Returns how many moved.
size_t NforSmoothGlintBands(const Image &albedo, const Image *alpha, int radius, double sigma,
                            double tensorSigma, double bound, double glintAlbedo, int reach,
                            double emitterAlbedo, Image *output);

}  // namespace mcd::ref
