// GLSL helpers of method `bayes`: the band a Mallat-layout coefficient belongs to, lgamma
// in float and the posterior mean of eq. 11 by the quadrature documented in
// cpu_reference/bayes_model.h (written again here; the reference shares no code).
#ifndef MCD_SHADERS_BAYES_MODEL_GLSL
#define MCD_SHADERS_BAYES_MODEL_GLSL

#include "bayes/bayes.h"

// Ceil-halving `level` times (host/wavelet.h LevelExtent).
int BayesExtent(int n, int level) {
    for (int k = 0; k < level; ++k) n = (n + 1) / 2;
    return n;
}

// The rectangle [r.x, r.z) x [r.y, r.w) of a level's band in orientation 0 HL, 1 LH, 2 HH.
ivec4 BayesBandRect(int width, int height, int level, int orientation) {
    int w = BayesExtent(width, level), h = BayesExtent(height, level);
    int lowW = (w + 1) / 2, lowH = (h + 1) / 2;
    if (orientation == 0) return ivec4(lowW, 0, w, lowH);
    if (orientation == 1) return ivec4(0, lowH, lowW, h);
    return ivec4(lowW, lowH, w, h);
}

// Band index (channel excluded: level * 3 + orientation) of coefficient (x, y), or -1 in
// the coarsest low-low band.
int BayesBandOf(int x, int y, int width, int height, int levels) {
    int w = width, h = height;
    for (int level = 0; level < levels; ++level) {
        int lowW = (w + 1) / 2, lowH = (h + 1) / 2;
        bool highX = x >= lowW, highY = y >= lowH;
        if (highX || highY) return level * 3 + (highX ? (highY ? 2 : 0) : 1);
        w = lowW;
        h = lowH;
    }
    return -1;
}

// log Gamma(x) for x > 0: shift to x >= 8 by the recurrence, then Stirling's series.
float BayesLgamma(float x) {
    float shift = 0.0;
    while (x < 8.0) {
        shift += log(x);
        x += 1.0;
    }
    float inv = 1.0 / x, inv2 = inv * inv;
    float series = inv * (1.0 / 12.0 - inv2 * (1.0 / 360.0 - inv2 * (1.0 / 1260.0)));
    return (x - 0.5) * log(x) - x + 0.91893853320467274 + series - shift;
}

// |x / s|^p, 0 at x = 0.
// The exponent is capped at 2^126: (|x|/s)^p overflows float for |x|/s above 7000 when
// p = 10 (measured: NaN tables, black output, at p_n 10 and s_n 0.01), and Inf - Inf in the
// log-sum-exp is NaN. A capped term weighs exp(-2^126) against the peak's: nothing.
float BayesPowAbs(float x, float s, float p) {
    float r = abs(x) / s;
    return r > 0.0 ? exp2(min(p * log2(r), 126.0)) : 0.0;
}

// Posterior mean of eq. 11 at y >= 0 for noise (sn, pn) and signal (sc, pc), with a
// running log-sum-exp (no 0/0 whatever the scales).
float BayesPosteriorMean(float y, float sn, float pn, float sc, float pc) {
    float a = min(sn, sc);
    float noiseWidth = sn * exp2(log2(float(BAYES_TAIL)) / pn);
    float reach = max(noiseWidth, sc * exp2(log2(float(BAYES_TAIL)) / pc));
    float t0 = asinh(-reach / a), t1 = asinh((y + reach) / a);
    float dt = min(1.0 / float(BAYES_STEPS_PER_WIDTH),
                   sn / (float(BAYES_STEPS_PER_WIDTH) * (y + noiseWidth + a)));
    float points = ceil((t1 - t0) / dt);
    int n = int(clamp(points, float(BAYES_MIN_POINTS), float(BAYES_MAX_POINTS)));
    dt = (t1 - t0) / float(n);
    // The grid weight a cosh(t) dt multiplies after the exp: it spans a few decades at
    // most, far from float's range, so only the log densities need the running maximum.
    float peak = 0.0, num = 0.0, den = 0.0;
    for (int k = 0; k < n; ++k) {
        float e = exp(t0 + (float(k) + 0.5) * dt);
        float c = 0.5 * a * (e - 1.0 / e), weight = 0.5 * a * (e + 1.0 / e);
        float l = -BayesPowAbs(y - c, sn, pn) - BayesPowAbs(c, sc, pc);
        if (k == 0 || l > peak) {
            float scale = k == 0 ? 0.0 : exp(peak - l);
            num = num * scale + weight * c;
            den = den * scale + weight;
            peak = l;
        } else {
            float w = weight * exp(l - peak);
            num += w * c;
            den += w;
        }
    }
    return num / den;
}

#endif
