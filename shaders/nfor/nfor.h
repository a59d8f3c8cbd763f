// Constants shared by the feature-regression kernels (method nfor) and their host code: the
// limits, the specialization constants and the numerical cut-offs. The CPU reference
// (cpu_reference/nfor.h) keeps its own copies.
#ifndef MCD_SHADERS_NFOR_NFOR_H
#define MCD_SHADERS_NFOR_NFOR_H

#define NFOR_LOCAL_SIZE 64
#define NFOR_MAX_CHANNELS 4   // colour channels
#define NFOR_MAX_FEATURES 10  // feature planes of the regression (albedo, normal, depth, pivot)
#define NFOR_MAX_RADIUS 10    // regression window half-size
#define NFOR_MAX_PATCH 3      // colour patch half-size
#define NFOR_MAX_CANDIDATES 4  // bandwidths
#define NFOR_NOISE_MAX_RADIUS 3
#define NFOR_PREFILTER_MAX_RADIUS 5
#define NFOR_PREFILTER_MAX_PATCH 2
#define NFOR_SURE_MAX_RADIUS 8

// Specialization constants: the colour's channel count and the feature planes' (the fit's
// arrays are sized by them); regress's candidates a dispatch (1 or 2, nfor/fit.h).
#define NFOR_SPEC_CHANNELS 0
#define NFOR_SPEC_FEATURES 1
#define NFOR_SPEC_CANDIDATES 2

// The noise estimate: divisors (albedo) at or under the floor are 1; neighbours whose
// divisors differ by more than the ratio are not compared; the median of chi^2_1.
#define NFOR_NOISE_ALBEDO_FLOOR 0.02
#define NFOR_NOISE_DIVISOR_RATIO 1.25
#define NFOR_CHI2_MEDIAN 0.454936423119572
// A direction counts with at least this many pairs divided alike; a pixel with no such
// direction takes the pairs of its neighbours divided as it is (divided or not), a
// direction counting with at least the second many.
#define NFOR_NOISE_MIN_PAIRS 3
#define NFOR_NOISE_MIN_RELAXED_PAIRS 2

// A distance term's denominator adds this times the two values' squares (a relative noise
// floor of 1% std, so that noise-free pixels compare by relative difference) and a tiny
// absolute floor; a term is at most NFOR_TERM_MAX.
#define NFOR_REL_EPS 1e-4
#define NFOR_TINY 1e-30
#define NFOR_TERM_MAX 25.0
// A weight exp(-e) with e above this is 0 (no denormals: float and double agree).
#define NFOR_EXP_CUT 30.0

#endif
