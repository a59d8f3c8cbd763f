// nfor's specks clamped (host/methods/nfor_specks.h), the CPU reference, in double.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd::ref {

// Each pixel p of `output` with mask 1, all 8 neighbours inside the frame and none of mask
// 0: with L the mean of a pixel's channels and n the rank-th
// largest L of its neighbours, where L_p > b = (1 + relative) n + floor, every channel
// becomes its value times b / L_p. L, n and b are read on the output before any change.
// With flatShare > 0, where the 5th largest L of the neighbours is at least flatShare x n,
// flatRelative takes relative's place.
void NforClampSpecks(const Image &mask, int rank, double relative, double floor, Image *output,
                     double flatShare = 0, double flatRelative = 0.1);

// Pixels on an exact ground: p with mask 1, all 8 neighbours inside the frame with mask 1,
// every channel of `clamped` at p equal to `input`'s, the neighbours' input colours all equal
// to each other in every channel (bit for bit) with a channel above 0, and p's input colour
// not equal to theirs. One flag per pixel.
std::vector<char> NforExactGround(const Image &input, const Image &clamped, const Image &mask);

// The variance layer the firefly clamp reads, lone samples capped: pixel p is a lone sample
// where, with m its colour's mean over the channels and s the mean over the channels of the
// square roots of its variances (negative ones as 0), m^2 < hits s^2; its in-frame
// neighbours (3x3, p left out) do not all hold the same colour bits; and m > ratio x the
// lower median of the neighbours' colour means (the finite ones; some finite, median above
// 0). A lone sample with no other lone sample in the (2 reach + 1)^2 window around it (cut at
// the frame) gets each channel of `variance` at p as min(its own, the lower median of its
// in-frame neighbours' finite values in that channel). `count`: the pixels capped.
Image NforCapLoneSamples(const Image &variance, const Image &color, double hits, double ratio,
                         int reach, size_t *count);

}  // namespace mcd::ref
