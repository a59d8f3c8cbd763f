// The pivot-image filter (Ershov et al., section 4), the CPU reference: pseudo-brightness
// z = L / L_a, the adaptive-radius plane fits of the square and its four quadrants (4.2,
// 4.3), the combined approximation (eqs. 11-12), the two-stage averaging (eq. 13) and the
// back-multiplication; and the cross-bilateral baseline of z. Written loop by loop in
// double, every window refitted from scratch (the GPU grows its sums ring by ring); the
// parameters are the GPU path's layout (PivotParams, host/params/pivot.h), taken as doubles.
//
// Readings of the paper, shared with the GPU path (host/methods/pivot.h states them too):
// - A pixel's pivot L_a is "far below the image's scale" when L_a <= floor x the mean of
//   max(L_a, 0) over the channel. Such pixels have no z, are left out of every fit and
//   average, and keep their input value in the output. So do pixels no fit reaches.
// - Noise: s = variance of z (the variance layer / L_a^2, or without one the sample
//   variance of z over the valid 3x3 neighbours), nu = s / zl^2 its relative version, zl
//   the mean z of the valid 3x3 neighbours. sigma in eq. 10 is nu; a pixel is fitted only
//   when nu <= goodNoise^2 (the threshold of section 4.2).
// - Eq. 10's distance term is read as d^2 / R^2 (dimensionless; as printed, d^2 / R would
//   leave e^-30 at the edge of a 30-pixel window).
// - Window growth (4.3) fits with eq. 10's weight without its distance term and with <z>
//   the centre's zl, which is what lets the GPU add one ring per step; the chosen radius is
//   then fitted once more with eq. 10 in full (<z> = mean z of the fitted pixels).
// - Growth stops at the first radius r >= 2 where (a) a quadrant's centre value differs
//   from the square's by more than disagreement x |Z| + 2 x the quadrant value's predicted
//   standard deviation (the radius is then r - 1, at least 2), or (b) the square's
//   predicted standard deviation at the centre is <= targetNoise x |Z|, or (c) r is
//   maxRadius or the square covers the image. Predicted variance of a fit at q:
//   (sum w^2 s / sum w) q^T M^-1 q, M the weighted normal matrix (exact for equal weights
//   and equal noise).
// - Normal term (n.n0)^4 for n.n0 > 1/2 else 0 (unit normals; two zero normals give 1, one
//   gives 0), object and part terms 0 when the ids differ; they multiply both the fit
//   weights ("effectively excluded from fitting", 4.3) and the averaging weight. The
//   boundary term w_b ("0 near projections of the boundaries") is 0 only for a pixel
//   beside other ids that mixes in a side far from its own (PivotRatioOf; the ids are the
//   first sample's: a light's rim seen as the ceiling, or the ceiling seen as the light):
//   as data it would lift or sink its side's fits around it (docs/methods/pivot.md). Other
//   pixels beside other ids are data to their side's fits and filtered
//   by them: the pivot, anti-aliased as the colour is, divides out most of their mix. Kept,
//   as they were, they drew dotted outlines along every id edge at low spp (issue 29). They
//   are no centres: a square there, mostly of other ids, grows far on few pixels of its own
//   and its fit, gathered far from the edge, misleads the dark floor beside it.
// - Eq. 13's base weight is exp(-d^2 / R0^2) of the centre's window (d^2 = dx^2 + dy^2),
//   normalised by the sum of the weights.
// - Eq. 13's sum over centres is taken as a quadrature: a centre of radius R0 takes part
//   only on its lattice, x0 and y0 multiples of step = the largest power of two <= R0 / 2
//   (1 below R0 = 4, at most 8), and then stands for the step^2 centres around it (weight
//   times step^2). Neighbouring squares of one radius overlap in all but a step/(2R0+1) <
//   1/4 slice per axis, so their fits are nearly the same: the lattice keeps more than 4
//   centres per axis of each square and sums far fewer terms (a finer step measured no
//   better).
//   Powers of two up to 8 keep the lattice the same in tiles starting on multiples of 8.
//   A pixel that no lattice centre reaches (a thin part between other ids) takes its own
//   fit at its place: eq. 11 of the square and quadrant 0 at (0, 0).
// - So only lattice centres need their square: a centre's growth stops at radius r when
//   r + 1's step does not divide x0 and y0 (r + 1 = 4, 8 or 16), as no radius from r + 1 on
//   would leave it on its lattice. The tests at r come first: a disagreement gives r - 1, a
//   quiet fit, the image's cover or the largest radius give r, all on the lattice. Otherwise
//   the centre is off its lattice: it keeps the growth fits of the square of radius r (no
//   distance term, <z> the centre's local mean) for the fallback above and is given the
//   radius r + 1, which marks it off its lattice for the gather. (Until issue #19's third
//   round the square of r + 1 was grown too, and a disagreement there kept the centre on
//   the lattice with radius r; the test at r + 1 cost a ring of 8 (r + 1) pixels of each of
//   most centres.) Radii of off-lattice centres are thus 4, 8 or 16, their squares 3, 7 or 15.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "host/params/pivot.h"

namespace mcd::ref {

// Plane layout of the fits: (a, b, c) of Z = a dx + b dy + c for the square, then quadrants
// 0..3, then the radius (-1: no fit). Coordinates (dx, dy) are relative to the centre.
// Quadrant 0: dx >= 0, dy >= 0; 1: dx <= 0, dy >= 0; 2: dx <= 0, dy <= 0; 3: dx >= 0,
// dy <= 0 (axes in both; eq. 11 assigns a pixel by dx >= 0 ? (dy >= 0 ? 0 : 3) :
// (dy >= 0 ? 1 : 2)). A quadrant without a fit repeats the square's plane.
constexpr int kPivotPlanes = 16;

// Optional guides: normals (3 channels) and ids (2 channels: object, part); nullptr when
// absent.
struct PivotGuides {
    const Image *normal = nullptr;
    const Image *ids = nullptr;
};

// Stage 1. z, s, nu, level, the median z of the valid 3x3 neighbours (the upper one of an
// even count), and noise, the mean of their variances s (without a variance input the
// window's sample variance, s itself; both the shading-edge test's, PivotAcrossEdge),
// channels as the color; nu = -1 marks pixels without z.
struct PivotRatio {
    Image z, s, nu, level, noise;
};
// With `ids`, a pixel on an object/part boundary (a 4-neighbour has other ids) is data like
// any other, unless it mixes in a side far from its own: the median z of the other ids'
// pixels within 2 lies over 2 spreads from the median of its own ids' (itself included; a
// side's spread is 1.4826 x the median distance to its median, the larger of the two), and
// its z over half its deviation (the larger of sqrt(s) and the spread) toward the other
// side. Then it gives no z and keeps its input (nu = -1).
PivotRatio PivotRatioOf(const Image &color, const Image &pivot, const Image *variance,
                        double floor, const Image *ids = nullptr);

// Stage 2. Fits of every centre (off eq. 13's lattice: its growth fits, see above):
// kPivotPlanes x channels planes, plane p of channel c at channel p * channels + c. `margin`
// (channels as the color), when not null, receives per centre the smallest relative distance of
// any growth or rank decision to its threshold: where it is tiny, float and double may decide
// differently.
Image PivotFit(const PivotRatio &ratio, const PivotGuides &guides, const PivotParams &params,
               Image *margin = nullptr);

// Eq. 13's lattice step for a centre of radius R0 (see above).
int PivotLatticeStep(double radius);

// Stage 3. Eqs. 11-13 and the back-multiplication; pixels without z or without any
// averaging weight keep their color. `edge`: the shading-edge test's sigmas (0: off).
Image PivotGather(const Image &color, const Image &pivot, const PivotRatio &ratio,
                  const Image &fits, const PivotGuides &guides, double edge);

// The shading-edge test (PivotParams::edge): levels zq and zc (PivotRatio::level) with
// noises sq and sc (PivotRatio::noise: a pixel's variance over its 3x3 window) lie across an
// edge when they differ by over kPivotEdgeContrast times the smaller and by over `sigmas`
// standard deviations of the levels' noise, read as (sq + sc) / 9. The final fit of a centre
// (not its growth, whose quadrant test still stops at the edge) leaves out data across an edge
// from the centre, and a pixel does not gather the fits of centres across one.
constexpr double kPivotEdgeContrast = 1;
bool PivotAcrossEdge(double zq, double sq, double zc, double sc, double sigmas);
// The relative distance of PivotAcrossEdge's two comparisons to their thresholds (the
// smaller; 1 without the test): where it is small float and double may decide apart.
double PivotEdgeMargin(double zq, double sq, double zc, double sc, double sigmas);

// The bilateral baseline: cross-bilateral filter of z guided by the pivot (and the guides),
// over fitted pixels, then back-multiplied.
Image PivotBilateral(const Image &color, const Image &pivot, const PivotRatio &ratio,
                     const PivotGuides &guides, const PivotParams &params);

// Section 8: one partial image with its own pivot and, optionally, variance.
struct PivotPartialImage {
    const Image *color = nullptr, *pivot = nullptr, *variance = nullptr;
};
// What PivotFilter reads; variance is optional. With partials, color, pivot and variance
// are unused: each partial is filtered against its own pivot, and the sum plus the
// remainder is the output.
struct PivotFilterInputs {
    const Image *color = nullptr, *pivot = nullptr, *variance = nullptr;
    PivotGuides guides;
    std::vector<PivotPartialImage> partials;
    const Image *remainder = nullptr;
};

// The whole method as `mcdenoise diff` compares it. With `stages`, also the images the GPU
// run keeps (host/methods/pivot.h), by the same names: "z", "nu", "fits" (plane fits only)
// and "output"; with partials, each partial's as "partial<k>.<stage>". params.meanRadius
// is the front end's (host/api/method_pivot.cpp), not the filter's.
Image PivotFilter(const PivotFilterInputs &in, const PivotParams &params,
                  std::vector<std::pair<std::string, Image>> *stages = nullptr);

// The normal and id terms, exposed for the tests. The normal term of a fit's data pixel
// (`data`) is times (1 - |n0|^8 (|n0| - |n|))^4 where the pixel's normal is the shorter
// (normals count as at most 1 long).
double PivotNormalTerm(const Image *normal, int x, int y, int x0, int y0, bool data = false);
double PivotIdTerm(const Image *ids, int x, int y, int x0, int y0);
double PivotBoundaryTerm(const Image *ids, int x, int y);

}  // namespace mcd::ref
