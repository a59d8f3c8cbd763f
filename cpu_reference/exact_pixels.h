// Pixels a frame knows exactly (host/common/exact_pixels.h), the CPU reference.
#pragma once

#include "host/image.h"

namespace mcd::ref {

// Each value of `output` whose input is finite and > 0 and whose variance (the value at the
// same pixel, in the same channel or in the only one) is exactly 0 becomes the input's. A
// variance of another size changes nothing.
// With reach > 0, per channel, with o the output before, e_p = o_p - in_p at each exact p, and
// for each other value q within max(|dx|, |dy|) <= reach of p the weight w_pq = max(0, in_q -
// o_q) where e_p > 0 and max(0, o_q - in_q) where e_p < 0 (0 at exact q): q gets G_q = the sum
// over p with e_p > 0 of e_p w_pq / sum_r w_pr, and gives L_q = the same over e_p < 0 of |e_p|
// w_pq / sum_r w_pr; its output becomes o_q + min(G_q, max(0, in_q - o_q)) - min(L_q,
// max(0, o_q - in_q)).
void KeepExactPixels(const Image &input, const Image &variance, Image *output, int reach = 0);

}  // namespace mcd::ref
