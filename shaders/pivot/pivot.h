// Constants shared by the pivot-filter kernels (Ershov et al., section 4) and their host
// code: the layout of the fit planes, the specialization constants and the numerical
// cut-offs. The CPU reference (cpu_reference/pivot_filter.cpp) keeps its own copies.
#ifndef MCD_SHADERS_PIVOT_PIVOT_H
#define MCD_SHADERS_PIVOT_PIVOT_H

// Fit planes per channel: (a, b, c) of the square, then of quadrants 0..3, then the radius
// (-1: no fit). Each channel has two buffers of its own, planes 0..7 in one and 8..15 in
// the other, so that a frame of up to 2048x2048 pixels, of any number of channels, stays
// within lavapipe's 128 MiB per binding. In each buffer a centre's 8 planes are adjacent:
// plane p at centre i = y * width + x is float i * PIVOT_PLANES_PER_BUFFER + p (the gather
// reads 6 planes of a centre: one or two cache lines, not 6 pages apart).
#define PIVOT_PLANES 16
#define PIVOT_PLANES_PER_BUFFER 8

// Specialization constants: the normal term and the object/part terms are compiled out
// when the frame has no normals or ids; the ratio kernel reads the variance layer or
// estimates the noise; the packed z, s, nu hold the shading-edge test's inputs or not.
#define PIVOT_SPEC_NORMALS 0
#define PIVOT_SPEC_IDS 1
#define PIVOT_SPEC_VARIANCE 2
#define PIVOT_SPEC_ZSN_TEXELS 3

// The ratio stage's packed input of the fit and the gather, per pixel adjacent: with the
// shading-edge test two vec4 texels, (z, s, nu, level) and (noise, 0, 0, 0); without it one,
// (z, s, nu, 0), which the test-off runs read at half the bytes.
#define PIVOT_ZSN_PLANES 4
#define PIVOT_ZSN_EDGE_PLANES 8

// Eq. 13 as a quadrature over the centres: a centre of radius R0 takes part when x0 and y0
// are multiples of its step (the largest power of two <= R0 / 2, at most this), with weight
// times step^2 (pivot/lattice.glsl). A step dividing the tiled run's window alignment (8)
// keeps tiles bit-exact.
#define PIVOT_LATTICE_MAX_STEP 8

#define PIVOT_LOCAL_SIZE 64
#define PIVOT_MAX_CHANNELS 4  // colour channels a frame may have

// The guide image's planes: normal x, y, z, object id, part id (what is absent is zero and
// compiled out). The GPU buffer holds a pixel's guides in one vec4 texel of
// PIVOT_GUIDE_STRIDE floats (one fetch): the normal, one longer than 1 normalised, and a
// label of the (object id, part id) pair, 1 + its index among the frame's distinct pairs,
// negated where the normal is zero (PivotGuideBuffer, pivot/guides.glsl). Labels only
// compare for equality, so a tile's own labels give the untiled result bit for bit.
// The gather's weight of the geometric term beside the data term (pivot/guides.glsl
// gatherTerm): a pixel no centre takes as data still takes its surface's fits.
#define PIVOT_GATHER_FALLBACK 1e-3
#define PIVOT_GUIDE_PLANES 5
#define PIVOT_GUIDE_STRIDE 4

// |z| above this makes a pixel invalid (z^2 and the fit sums stay finite in float); the
// variance of z is clamped to its square.
#define PIVOT_Z_MAX 1e18
// A weight exp(-e) with e above this is 0 (no denormals: float and double agree).
#define PIVOT_EXP_CUT 30.0
// A pixel beside other ids mixes in a side far from its own when the medians of z of its
// own ids and of the others within PIVOT_SIDE_RADIUS lie over PIVOT_SIDE_GAP of their
// spreads apart, and its z over PIVOT_SIDE_TOWARD of its deviation toward the other: it
// gives no data and keeps its input (the CPU reference's kSideGap, kSideToward,
// kSideRadius, kMadSigma).
#define PIVOT_SIDE_GAP 2.0
#define PIVOT_SIDE_TOWARD 0.5
#define PIVOT_SIDE_RADIUS 2

// A median absolute distance times this estimates a Gaussian's standard deviation.
#define PIVOT_SIDE_MAD_SIGMA 1.4826
// Floor of denominators that may be zero.
#define PIVOT_TINY 1e-30
// An elimination pivot at or below this fraction of its raw second moment drops the unknown.
#define PIVOT_RANK_EPS 1e-4
// The shading-edge test (pivot/edge.glsl): two levels of z (3x3 medians) lie across an edge
// when they differ by over this times the smaller as well as by the given sigmas of their
// noise.
#define PIVOT_EDGE_CONTRAST 1.0

#endif
