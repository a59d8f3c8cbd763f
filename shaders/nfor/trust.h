// nfor: where the colour distance trusts the albedo (nfor/distance.h's illumination marks
// it, term compares colour / albedo only where both ends of a pair are trusted). Per pixel p,
// over the 3x3 window around p (pixels inside the frame), each albedo a taken at least
// NFOR_NOISE_ALBEDO_FLOOR and colour channel c read against albedo channel min(c,
// albedoChannels - 1): the relative roughness of the albedo R_a = sum_c var(a_c) / sum_c
// mean(a_c)^2, of the colour R_C alike and of colour / albedo R_z (z = C / a per pixel); the
// variances are the mean squared deviations from the window's means (two passes). Where R_a
// > noise and R_z > (1 + NFOR_TRUST_TIE) R_C the albedo is noise (it varies, and dividing by it
// roughens the colour rather than smoothing it: glossy metal, whose albedo follows the sampled
// bounce, not texture the colour follows): trust 0; elsewhere 1. The ratios are compared
// cross-multiplied (a black window is trusted). One invocation per pixel.
// The albedo here is floored, not left undivided at or below the floor as the distance's
// divisor is: z stays continuous across the floor, so that a window straddling it (dark
// texture beside black) does not read the jump from C / a to C as the albedo roughening the
// colour. The two agree wherever the window's albedos are above the floor. NaN albedos are
// floored (the distance leaves them undivided).
#ifndef MCD_SHADERS_NFOR_TRUST_H
#define MCD_SHADERS_NFOR_TRUST_H

#include "nfor/nfor.h"

#define NFOR_TRUST_COLOR 0
#define NFOR_TRUST_ALBEDO 1
#define NFOR_TRUST_OUT 2
#define NFOR_TRUST_BINDINGS 3
// A window whose colour holds one non-zero value has R_z = R_C exactly: ties (and their
// roundings) are trusted.
#define NFOR_TRUST_TIE 1e-3

#ifdef __cplusplus
namespace mcd::shader {
struct NforTrustPush {
#else
layout(push_constant) uniform NforTrustPush {
#endif
    int width;
    int height;
    int albedoChannels;  // 1, or at least the colour's
    float noise;         // the albedo's relative roughness above which it may be noise
#ifdef __cplusplus
};
static_assert(sizeof(NforTrustPush) == 16);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
