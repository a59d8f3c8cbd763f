// Ershov's tracing filter (section 5), the CPU reference: the gather of eq. 15 with the
// self weight of eq. 16, the re-weighting C of eq. 14 and the inter-pixel weight of
// eq. 17, written loop by loop in double from the paper.
//
// Readings of the paper (the GPU kernel, shaders/tracing/, follows them):
// - Eq. 16's step function is the neighbour's horizon, Theta(u . n_{A(v')}): the text
//   under it says the self weight is 1 for directions that "could not be emitted for p'".
// - A neighbour's sample u' lands in p with w(p <- p', u') f_p(u') cos_p(u') L(u') /
//   pdf_{p'}(u'), i.e. eq. 14's C times the neighbour's own estimate when the neighbour
//   samples u' in proportion to f cos (eq. 2); with the pdf the renderer really used it is
//   unbiased for any sampler whose density covers p's lobes.
// - f_p is the pixel's mean textured BSDF (TracingSurface); F of eq. 17 compares the two
//   geometries under p's material (scalar: the channel means of its lobe weights), and is
//   infinite (weight 0) where either side is 0, which is also Theta of eq. 14.
// - The neighbourhood is the disk |p - p'| <= radius minus p; neighbours without a smooth
//   surface, or outside the records' rows, take no part. C_p = min(1, selfFloor / sum of
//   eq. 17's fixed parts over the neighbourhood).
// - A neighbour sample with pdf <= 0 or a non-finite pdf or radiance gives nothing; a
//   pixel's own samples always give their `own` (a NaN stays in its pixel).
// - A neighbour whose samples reach its surface only in part (`valid` = that share: the
//   rest saw the sky, an emitter or a mirror) lends from that share only, so its weight in
//   eq. 16's self term is scaled by it; otherwise the pixel would give up more light than
//   it gets back (measured dark beside half-covered neighbours).
// - gamma = 0 switches the variable part off (weight C_p x fixed part wherever both lobes
//   are positive), rather than 0 x F^2 being NaN for an infinite F.
#pragma once

#include <vector>

#include "host/tracing.h"

namespace mcd::ref {

// The filtered part of rows [outY0, outY0 + outRows) (frame rows; they must lie inside the
// records), 3 floats per pixel, row-major. A pixel without a smooth surface gets the mean
// of its samples' `own`. Throws std::invalid_argument for inconsistent records or
// parameters (radius, alpha, beta, gamma finite and >= 0, selfFloor in [0, 1]).
// `magnitude`, when given, receives per pixel and channel the sum of the sizes of the terms
// (|own| / spp for the own samples, C_p x fixed part x |f cos L / pdf| / spp for the lent
// ones): what a float twin's rounding error is proportional to.
std::vector<float> TracingFilter(const TracingRecords &records, const TracingParams &params,
                                 int outY0, int outRows,
                                 std::vector<float> *magnitude = nullptr);

// f cos of a surface's smooth lobes towards u (0 below its horizon), per channel.
void TracingBsdfCos(const TracingSurface &surface, const double u[3], double out[3]);

}  // namespace mcd::ref
