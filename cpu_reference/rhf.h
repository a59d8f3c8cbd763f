// Ray Histogram Fusion (Delbracio et al., IPOL 2015), the CPU reference: Algorithm 2 (one
// scale) and Algorithm 3 (multi-scale) written as plain loops, with the choices the
// authors' tool makes where the paper leaves them open (issue #4). In double where it
// matters; nothing is shared with the GPU path but the parameters' layout (RhfParams,
// host/params/rhf.h), whose floats are taken as doubles here.
//
// Histograms are an Image of 3n+1 channels: channel c*n+b is bin b of colour c (R, G, B),
// the last channel is the pixel's sample count.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "host/params/rhf.h"

namespace mcd::ref {

// Scales actually filtered: scale s >= 1 is used only while its image is at least as big
// as the search window (2b+1) both ways ("leave out what the frame does not need").
int RhfScalesUsed(int width, int height, const RhfParams &params);

// Chi-square patch distance between the patches of half-size w0 centred at (x0, y0) and
// (x1, y1): the sum of the counted pixel terms over the patch and the bins, divided by the
// number of counted terms + 1e-4. With brightVeto > 0 it is -1 (not a candidate) when a
// pixel pair's counted terms in the saturated bins (the last two of each colour: samples
// above the histogram's range M) sum to more than brightVeto times the harmonic mean
// 2 n_x n_y / (n_x + n_y) of the pair's sample counts.
double RhfPatchDistance(const Image &hist, int x0, int y0, int x1, int y1, int w0,
                        double brightVeto = 0);

// Algorithm 2, lines 10-17, as the tool selects: distances are one window's candidates in
// its order (column by column), vetoed ones left out. `nearest` passes of a selection sort
// (each takes the first smallest of the rest and swaps it to the front) pick the nearest;
// every candidate closer than the threshold is taken too. Returns one flag per candidate.
std::vector<bool> RhfSelect(const std::vector<double> &distances, int nearest,
                            double threshold);

// Not in the paper: per pixel the bright samples (the last two bins of each colour) summed
// over its (2 patchHalf + 1)^2 box cut at the image's edges, in float, row by row, a
// pixel's colours and bins first. Width x height, row-major.
std::vector<float> RhfBrightPool(const Image &hist, int patchHalf);

// Algorithm 2 on one scale: kNN (with knn > 0, the knn + 1 nearest, the patch itself among
// them, ties resolved as the tool's selection sort over the window column by column does)
// plus every patch closer than the threshold, binary weights, aggregation over the
// patches covering each pixel. Vetoed patches are no candidates; with brightPool > 0 nor
// are those whose RhfBrightPool, Q, differs from the centre's, P, as rates over the boxes'
// pixel counts aQ, aP (cut at the image's edges): (P/aP - Q/aQ)^2 > brightPool (P/aP^2 +
// Q/aQ^2) (in float). A pixel no selected patch covers keeps its value.
Image RhfSingleScale(const Image &color, const Image &hist, int patchHalf, int searchHalf,
                     double threshold, int knn, double brightVeto = 0, double brightPool = 0);

// Not in the paper (issue #19, a bound the GPU's pixel terms use to leave bins out): for
// every bin plane i < 3n, row y and block of `block` pixels of the row (the last block cut
// at the edge), the largest h_i histScale over the block's pixels whose count times
// histScale is non-zero, -FLT_MAX when none has one. In float, as the GPU reads the bins.
// An Image of 3n channels, ceil(width / block) x height.
Image RhfBlockMax(const Image &hist, float histScale, int block);

// The symmetric boundary of the tool's samplers: index i of a line of n, mirrored about the
// edges (period 2n, the edge pixel repeated).
int RhfMirror(int i, int n);

// D_s as the tool's Gaussian sampler: output pixel x is the Gaussian of standard deviation
// sigma centred on input position (x + 0.5) 2^s - 0.5 (pixel-centre coordinates), taps
// j in [floor((x + 0.5) 2^s) - h, + h] with h = ceil(sigma sqrt(4 ln 10)), normalised,
// mirrored edges; the result is ceil(W / 2^s) x ceil(H / 2^s).
Image RhfGaussianDownsample(const Image &image, int s, double sigma);

// U: bicubic (Keys, a = -0.5) interpolation of `coarse` onto a width x height grid with the
// pixel centres aligned: fine x sits at coarse (x + 0.5) coarse.width / width - 0.5;
// mirrored edges.
Image RhfBicubicUpsample(const Image &coarse, int width, int height);

// Algorithm 3: the whole filter. With `stages`, also the images the GPU run keeps
// (RhfResult::stages), by the same names, coarse to fine: D_s of the colour ("color s<k>",
// s >= 1), each scale's filtered image ("filtered s<k>") and, below the coarsest, its
// recombination ("combined s<k>"). The output is raw: params.keepNegative is the GPU
// pipeline's clamp, left to the caller here.
Image Rhf(const Image &color, const Image &hist, const RhfParams &params,
          std::vector<std::pair<std::string, Image>> *stages = nullptr);

}  // namespace mcd::ref
