// Constants of method `bayes` (Xu & Pattanaik) shared by its GLSL kernels, the host and
// the CPU reference: layout and model limits, never algorithm.
//
// Bands: a `levels`-level Mallat DWT of a C-channel image has 3 detail bands per level
// and channel, numbered band = (channel * levels + level) * 3 + orientation, orientation
// 0 = HL (x high, y low), 1 = LH (x low, y high), 2 = HH. The coarsest low-low band is kept.
//
// Per band the moments buffer holds BAYES_MOMENT_STRIDE floats: E[y^2], E[y^4], max |y|,
// count; the params buffer BAYES_PARAM_STRIDE floats: s_n, p_n, s_c, p_c, fit (BAYES_FIT_*),
// y_max, the table's scale b and step du; the table BAYES_TABLE_SIZE floats: the posterior
// mean at y_i = b sinh(i du), i = 0..BAYES_TABLE_SIZE-1 (non-negative y; it is odd).
#ifndef MCD_SHADERS_BAYES_BAYES_H
#define MCD_SHADERS_BAYES_BAYES_H

#define BAYES_MOMENT_STRIDE 4
#define BAYES_PARAM_STRIDE 8
#define BAYES_TABLE_SIZE 256

// Bracket of the signal shape p_c solved through the kurtosis ratio; a kurtosis outside
// [kurtosis(BAYES_P_HI), kurtosis(BAYES_P_LO)] clamps p_c to the nearer end.
#define BAYES_P_LO 0.3
#define BAYES_P_HI 3.0

// Fits of a band (params[4]).
#define BAYES_FIT_SOLVED 0     // (s_c, p_c) solve eqs. 17-18
#define BAYES_FIT_NO_SIGNAL 1  // band variance <= noise variance: c^ = 0
#define BAYES_FIT_P_LOW 2      // kurtosis above the reachable range: p_c = BAYES_P_LO
#define BAYES_FIT_P_HIGH 3     // kurtosis below it (or 4th moment <= noise's): p_c = BAYES_P_HI
#define BAYES_FIT_NO_NOISE 4   // s_n < BAYES_MIN_NOISE_S: c^ = y
#define BAYES_FIT_EMPTY 5      // no coefficients in the band

// A band whose noise s is below this is NO_NOISE (kept as is). In the log domain s_n is a
// relative error of the pixel values: 1e-6 is below what any render carries and at the
// float resolution of the log image itself (1 ulp of a log value near 8), so keeping the
// coefficient changes the output by about s_n relatively: invisible. Below it the float
// quadrature breaks down: the table's y/s_n range and (|y - c| / s_n)^p_n overflow and the
// grid cannot resolve the posterior (measured: NaN bands, black output, at s_n 1e-19).
#define BAYES_MIN_NOISE_S 1e-6

// A band whose signal variance is below this fraction of the noise variance is NO_SIGNAL:
// s_c would be so small that the prior is a spike at 0 and c^ is 0 to within it.
#define BAYES_MIN_SIGNAL_FRACTION 1e-6

// Quadrature of eq. 11 (see cpu_reference/bayes_model.h): terms below exp(-BAYES_TAIL) of
// the peak are cut; the grid step is at most 1/BAYES_STEPS_PER_WIDTH of the noise width
// over [0, y] and the point count is clamped to [BAYES_MIN_POINTS, BAYES_MAX_POINTS].
#define BAYES_TAIL 40.0
#define BAYES_STEPS_PER_WIDTH 4.0
#define BAYES_MIN_POINTS 64
#define BAYES_MAX_POINTS 65536

#endif
