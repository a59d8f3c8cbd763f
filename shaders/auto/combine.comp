#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/combine.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(std430, binding = AUTO_COMBINE_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = AUTO_COMBINE_CANDIDATES) readonly buffer Candidates { float candidates[]; };
layout(std430, binding = AUTO_COMBINE_ERRORS) readonly buffer Errors { float errors[]; };
layout(std430, binding = AUTO_COMBINE_OUTPUT) writeonly buffer Output { float outputs[]; };
layout(std430, binding = AUTO_COMBINE_WEIGHTS) writeonly buffer Weights { float weights[]; };
layout(std430, binding = AUTO_COMBINE_VARIANCE) readonly buffer Variance { float variance[]; };

bool finite(float v) {
    return !(isnan(v) || isinf(v));
}

int plane, at, channels, count;
// Per candidate at this pixel, found once: usable, and its weight before normalisation.
bool usableAt[AUTO_MAX_CANDIDATES];
float weightAt[AUTO_MAX_CANDIDATES];

// Whether candidate k has a finite estimate and output at the pixel.
bool usable(int k) {
    if (!finite(errors[k * plane + at])) return false;
    for (int c = 0; c < channels; ++c)
        if (!finite(candidates[(k * channels + c) * plane + at])) return false;
    return true;
}

// Candidate k's weight before normalisation.
float weightOf(int k, int best) {
    if (push.mode == AUTO_MODE_SELECT) return k == best ? 1.0 : 0.0;
    if (!usableAt[k]) return 0.0;
    return pow(max(errors[k * plane + at], push.floorError), -push.power);
}

// Relative mode: channel c's value minimising the weighted relative squared error over the
// candidates, with equal weights or the estimates'; their weighted mean where the sum of
// weights over c_k^2 + 0.01 is 0 or beyond a float. With darkLimit a candidate darker than
// the weighted mean m counts as if its square were m^2 / darkLimit.
float relativeValue(int c, bool equal, float total, int usableCount, float darkLimit) {
    float mean = 0.0;
    for (int k = 0; k < count; ++k) {
        float wk = equal ? (usableAt[k] ? 1.0 : 0.0) : weightAt[k];
        if (wk > 0.0)
            mean += wk / (equal ? float(usableCount) : total) *
                    candidates[(k * channels + c) * plane + at];
    }
    float floorSquare = darkLimit > 0.0 ? mean * mean / darkLimit : 0.0;
    float num = 0.0, den = 0.0;
    for (int k = 0; k < count; ++k) {
        float wk = equal ? (usableAt[k] ? 1.0 : 0.0) : weightAt[k];
        if (!(wk > 0.0)) continue;
        float v = candidates[(k * channels + c) * plane + at];
        // Beyond a float's square, a value weighs nothing here.
        float square = v * v;
        if (floorSquare > square) square = floorSquare;
        float a = wk / (square + AUTO_REL_OFFSET);
        num += a * v;
        den += a;
    }
    float f = num / den;
    return den > 0.0 && !isinf(den) && finite(f) ? f : mean;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    count = push.count;
    if (x >= w) return;
    plane = w * h;
    at = y * w + x;
    channels = push.channels;
    int best = -1;
    for (int k = 0; k < count; ++k) {
        usableAt[k] = usable(k);
        if (usableAt[k] && (best < 0 || errors[k * plane + at] < errors[best * plane + at]))
            best = k;
    }
    float total = 0.0;
    for (int k = 0; k < count; ++k) {
        weightAt[k] = weightOf(k, best);
        total += weightAt[k];
    }
    bool none = !(total > 0.0) || isinf(total);
    // Every usable estimate under the floor: the median of the usable candidates (relative
    // mode: equal weights).
    bool relative = push.mode == AUTO_MODE_RELATIVE;
    int usableCount = 0;
    bool allUnder = push.mode == AUTO_MODE_WEIGHTS_MEDIAN || relative;
    for (int k = 0; k < count; ++k)
        if (usableAt[k]) {
            ++usableCount;
            allUnder = allUnder && errors[k * plane + at] < push.floorError;
        }
    // The median needs no weights: it holds even where their total overflows.
    bool median = allUnder && usableCount > 0 && !relative;
    bool equal = relative && usableCount > 0 && allUnder, noisy = false;
    if (relative && usableCount > 0 && !equal) {
        // Noise beyond what the estimates resolve: v over the equal-weight value's
        // denominator, averaged over channels (a NaN variance is not noise).
        float ratio = 0.0;
        for (int c = 0; c < channels; ++c) {
            float u = relativeValue(c, true, total, usableCount, 0.0);
            ratio += variance[c * plane + at] / (u * u + AUTO_REL_OFFSET);
        }
        noisy = equal = ratio / float(channels) > push.noiseLimit;
    }
    for (int k = 0; k < count; ++k)
        weights[k * plane + at] = equal  ? (usableAt[k] ? 1.0 / float(usableCount) : 0.0)
                                  : none ? 0.0
                                         : weightAt[k] / total;
    for (int c = 0; c < channels; ++c) {
        if (relative && (equal || !none)) {
            // At a noisy pixel the dark candidates weigh in full: there they remove the noise.
            outputs[c * plane + at] =
                relativeValue(c, equal, total, usableCount, noisy ? 0.0 : push.darkLimit);
            continue;
        }
        if (median) {
            // Insertion sort of the usable candidates' values (at most AUTO_MAX_CANDIDATES).
            float v[AUTO_MAX_CANDIDATES];
            int n = 0;
            for (int k = 0; k < count; ++k) {
                if (!usableAt[k]) continue;
                float value = candidates[(k * channels + c) * plane + at];
                int i = n++;
                for (; i > 0 && v[i - 1] > value; --i) v[i] = v[i - 1];
                v[i] = value;
            }
            outputs[c * plane + at] = n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
            continue;
        }
        float sum = 0.0;
        for (int k = 0; k < count; ++k) {
            float wk = none ? 0.0 : weightAt[k] / total;
            if (wk > 0.0) sum += wk * candidates[(k * channels + c) * plane + at];
        }
        outputs[c * plane + at] = none ? color[c * plane + at] : sum;
    }
}
