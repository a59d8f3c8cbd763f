// nfor's lights spread (host/methods/nfor_lights.h), the CPU reference, in double.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// An emitter: a pixel whose largest albedo channel is above emitterAlbedo; its share s is
// weakShare where that channel is below weakAlbedo, else strongShare. With v the output as
// it came in, a pixel that is no emitter becomes v plus the sum of s_q v_q over its 4
// neighbours q that are emitters of s_q > 0 and finite v_q; such an emitter becomes v (1 - s
// m), m its 4 neighbours inside the frame that are no emitter. With `alpha`, a pixel whose
// alpha is not above 0 is left as it is and counts neither as an emitter nor as a neighbour
// that receives.
void NforSpreadLights(const Image &albedo, const Image *alpha, double emitterAlbedo,
                      double weakAlbedo, double weakShare, double strongShare, Image *output);

// The rim hits (host/methods/nfor_lights.h). With v the output as it came in and m(q) the
// mean of q's channels: an emitter p of largest albedo channel a_p, finite output and alpha
// above 0 (or no alpha) is a rim pixel where some other such emitter q within `radius`
// (Chebyshev) has a_q >= coreRatio a_p (those q: its core K_p), some of its 8 neighbours is no
// emitter with alpha above 0 and a finite colour mean, and m(v_p) > t_p = sqrt(max(g, 0)
// m(color_p)), g the median of those neighbours' colour means and m(color_p) finite and
// above 0. Such a p becomes v_p t_p / m(v_p); in each channel the light it loses, L_p = v_p (1
// - t_p / m(v_p)), goes to K_p, each q taking L_p max(v_q, 0) / sum over K_p of max(v, 0), or
// L_p / |K_p| where that sum is 0. coreRatio 0: off.
void NforFoldRimHits(const Image &color, const Image &albedo, const Image *alpha,
                     double emitterAlbedo, double coreRatio, int radius, Image *output);

}  // namespace mcd::ref
