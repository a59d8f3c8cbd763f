#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/solve.h"
#include "bayes/model.glsl"

layout(local_size_x = BAYES_SOLVE_LOCAL_SIZE) in;
layout(std430, binding = BAYES_SOLVE_MOMENTS) readonly buffer Moments { float moments[]; };
layout(std430, binding = BAYES_SOLVE_PARAMS) writeonly buffer Params { float params[]; };
layout(std430, binding = BAYES_SOLVE_NOISE) readonly buffer Noise { float noise[]; };

float LogKurtosis(float p) {
    return BayesLgamma(5.0 / p) + BayesLgamma(1.0 / p) - 2.0 * BayesLgamma(3.0 / p);
}

void main() {
    int band = int(gl_GlobalInvocationID.x);
    if (band >= push.bands) return;
    float m2 = moments[band * BAYES_MOMENT_STRIDE + 0];
    float m4 = moments[band * BAYES_MOMENT_STRIDE + 1];
    float yMax = moments[band * BAYES_MOMENT_STRIDE + 2];
    float count = moments[band * BAYES_MOMENT_STRIDE + 3];
    float sn = noise[band], pn = push.pn;
    int fit = BAYES_FIT_SOLVED;
    float sc = 0.0, pc = 0.0;
    if (count == 0.0) {
        fit = BAYES_FIT_EMPTY;
    } else if (sn < float(BAYES_MIN_NOISE_S)) {
        fit = BAYES_FIT_NO_NOISE;
    } else {
        float varN = sn * sn * exp(BayesLgamma(3.0 / pn) - BayesLgamma(1.0 / pn));
        float m4N = varN * varN * exp(LogKurtosis(pn));
        float varC = m2 - varN;
        bool finite = (floatBitsToUint(m2) & 0x7f800000u) != 0x7f800000u &&
                      (floatBitsToUint(m4) & 0x7f800000u) != 0x7f800000u;
        if (!finite || !(varC > float(BAYES_MIN_SIGNAL_FRACTION) * varN)) {
            fit = BAYES_FIT_NO_SIGNAL;
        } else {
            float m4C = m4 - m4N - 6.0 * varC * varN;
            if (!(m4C > 0.0)) {
                pc = float(BAYES_P_HI);
                fit = BAYES_FIT_P_HIGH;
            } else {
                float target = log(m4C) - 2.0 * log(varC);
                float lo = float(BAYES_P_LO), hi = float(BAYES_P_HI);
                if (target >= LogKurtosis(lo)) {
                    pc = lo;
                    fit = BAYES_FIT_P_LOW;
                } else if (target <= LogKurtosis(hi)) {
                    pc = hi;
                    fit = BAYES_FIT_P_HIGH;
                } else {
                    for (int i = 0; i < 40; ++i) {
                        float mid = 0.5 * (lo + hi);
                        if (LogKurtosis(mid) > target)
                            lo = mid;
                        else
                            hi = mid;
                    }
                    pc = 0.5 * (lo + hi);
                }
            }
            sc = sqrt(varC * exp(BayesLgamma(1.0 / pc) - BayesLgamma(3.0 / pc)));
        }
    }
    int at = band * BAYES_PARAM_STRIDE;
    params[at + 0] = sn;
    params[at + 1] = pn;
    params[at + 2] = sc;
    params[at + 3] = pc;
    params[at + 4] = float(fit);
    params[at + 5] = yMax;
    params[at + 6] = sn;
    params[at + 7] = fit != BAYES_FIT_NO_NOISE ? asinh(yMax / sn) / float(BAYES_TABLE_SIZE - 1) : 0.0;
}
