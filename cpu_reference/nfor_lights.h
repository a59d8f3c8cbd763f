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

}  // namespace mcd::ref
