// Ershov's tracing filter (section 5): what the renderer hands the gather. For the camera
// paths whose first hit A is a diffuse or glossy surface seen directly (section 8's partial
// 0), the light that reaches A along the sampled second segment u may be re-used by the
// neighbouring pixels, re-weighted for their surfaces (eqs. 14-17). Everything else (light
// before A, next-event estimation at A, the mirror lobe at A, paths with a mirror prefix)
// stays the pixel's own. Section 8: partial k (A reached after k mirror bounces) takes the
// same records of its own, filtered on their own: its surface's lobe weights carry the
// mirror chain's weights, a sample's pdf the odds of its mirror prefix, `radiance` no prefix.
#pragma once

#include <vector>

#include "host/params/tracing.h"

namespace mcd {

// The surface a pixel sees (its A(v)), one per pixel. The lobe weights are the textured
// weights averaged over the pixel's partial-0 samples: f is linear in them, so the
// neighbours' light re-weighted with the mean BSDF has the expectation of the pixel's own.
struct TracingSurface {
    float position[3];  // A, world space (eq. 17 has no term for it: kept for a depth term
                        // and for inspection; the gathers do not read it)
    float normal[3];    // shading normal at A, unit
    float wo[3];        // direction from A towards the camera, unit
    float diffuse[3];   // Lambert weight: f cos = diffuse cos / pi
    float glossy[3];    // glossy weight: f cos = glossy vMF(u; reflect(-wo, n), kappa)
    float kappa;        // vMF concentration
    float valid;        // the share of the pixel's samples that reach this surface (their
                        // records are the only ones it lends); 0: nothing to filter
};

// One camera sample of a pixel. A sample whose path did not continue from A through a
// smooth lobe (a mirror prefix, the mirror lobe at A, the sky, an emitter) has pdf 0 and
// only its `own` counts (it is 0 for such samples, whose light is all in `rest`).
struct TracingSample {
    float direction[3];  // u: the sampled direction leaving A, unit
    float pdf;           // density of u given the pixel's A, lobe choice included: the
                         // diffuse and glossy sampling densities weighted by their
                         // probabilities of being picked (sums to < 1 when a mirror
                         // lobe takes the rest); 0: no record
    float radiance[3];   // light arriving at A along u (no emitter seen directly from A:
                         // next-event estimation at A counted it, and that stays own)
    float own[3];        // this sample's filtered-part contribution to its own pixel as
                         // the renderer estimated it (the plain Monte Carlo value)
};

// The records of rows [y0, y0 + rows) of a frame `width` pixels wide, `spp` samples per
// pixel: surfaces[y * width + x], samples[(y * width + x) * spp + s] (y relative to y0).
struct TracingRecords {
    int width = 0, rows = 0, y0 = 0, spp = 0;
    std::vector<TracingSurface> surfaces;
    std::vector<TracingSample> samples;
};

}  // namespace mcd
