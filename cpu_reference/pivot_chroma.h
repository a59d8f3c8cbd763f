// CPU reference of the tinted fits' mend (host/common/pivot_chroma.h): a pixel whose fitted
// chroma is off its window's input chroma by more than the window's noise allows, where the
// window's input agrees with its own, keeps its brightness and takes the window's chroma.
#pragma once

#include <cstddef>

#include "host/image.h"

namespace mcd::ref {

// For each pixel p whose output differs from its colour in some channel (n >= 2 channels):
// W, the pixels q within 2 of p in x and y, inside the image, of p's objectId and partId
// (when given), with every C(q), V(q), P(q) finite and V, P >= 0 (p among them). With
// S_c = sum_W C_c, G_c = sum_W P_c, U_c = sum_W V_c (P, V of one channel read for every c),
// P_c(p) > 0 and G_c > 0: e_c = P_c(p) S_c / G_c, u_c = P_c(p)^2 U_c / G_c^2. For a colour a
// of variances v, with sum A > 0: k_c = a_c / A, noise(a, v) = sum_c sqrt(v_c (1 - k_c)^2 +
// k_c^2 sum_{j != c} v_j) / A, and ramp(d, a, lo, hi) = 0 where d <= lo a, 1 where d >= hi a,
// else (d - lo a) / ((hi - lo) a). With O the output, E = sum e > 0, sum O > 0: the weight
// w = ramp(sum_c |O_c / sum O - e_c / E|, noise(e, u), 1.5, 5), times (where sum C(p) > 0)
// 1 - ramp(sum_c |C_c(p) / sum C(p) - e_c / E|, noise(C(p), V(p)), 2, 4), times (where
// sum V(p) > 0) 1 - ramp(|E - sum C(p)|, sqrt(sum V(p) + sum u), 2, 4). Where w > 0, with
// T_c = sum O x e_c / E (as float), each T_c >= 0 and, with bound > 0, |T_c - C_c(p)| <=
// bound x NoiseSpread(V, c, p) unless that is below 0: O_c = O_c + w (T_c - O_c) (else
// the pixel stays). Returns the pixels moved.
size_t KeepWindowChroma(const Image &color, const Image &pivot, const Image &variance,
                        const Image *objectId, const Image *partId, double bound,
                        Image *output);

}  // namespace mcd::ref
