#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/noise.h"
#include "nfor/sorted.glsl"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(binding = NFOR_NOISE_IMAGE) uniform samplerBuffer values;
layout(binding = NFOR_NOISE_DIVISOR) uniform samplerBuffer divisor;
layout(std430, binding = NFOR_NOISE_OUTPUT) writeonly buffer Output { float outputs[]; };

const int kMaxPairs = (2 * NFOR_NOISE_MAX_RADIUS + 1) * (2 * NFOR_NOISE_MAX_RADIUS + 1);
int w, h, c;

// The divisor at (x, y): the albedo's channel above the floor, else 0 (not divided).
float divisorAt(int x, int y) {
    if (push.divisorChannels == 0) return 0.0;
    float a = texelFetch(divisor, (min(c, push.divisorChannels - 1) * h + y) * w + x).x;
    return a > float(NFOR_NOISE_ALBEDO_FLOOR) ? a : 0.0;
}

// Whether divisors a and b divide alike: both not, or both within the ratio.
bool alike(float a, float b) {
    float ratio = float(NFOR_NOISE_DIVISOR_RATIO);
    if (a == 0.0 || b == 0.0) return a == b;
    return a <= b * ratio && b <= a * ratio;
}

float zAt(int x, int y, float a) {
    float value = texelFetch(values, (c * h + y) * w + x).x;
    return a > 0.0 ? value / a : value;
}

bool inside(int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h;
}

// Whether the pair (a0, a1) counts for a pixel of divisor a: both divided alike to it, or
// (relaxed) both divided where it is, both not where it is not, and the pixel itself in
// neither (it may be a firefly, and a relaxed direction has few pairs).
bool counts(float a, float a0, float a1, bool relaxed, bool centre) {
    if (relaxed) return !centre && (a0 > 0.0) == (a > 0.0) && (a1 > 0.0) == (a > 0.0);
    return alike(a, a0) && alike(a, a1);
}

// The smallest over the directions with at least minPairs pairs of the median half squared
// difference over the median of chi^2_1 (with push.sparse, where that median is 0, the mean
// of the half squared differences); -1 where no direction has them.
float smallestMedian(int x, int y, float a, bool relaxed, int minPairs) {
    const ivec2 dirs[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    int r = push.radius;
    float best = -1.0;
    float halves[kMaxPairs];
    for (int d = 0; d < 4; ++d) {
        // Insertion into a sorted list as the pairs come.
        int n = 0;
        for (int v = y - r; v <= y + r; ++v)
            for (int u = x - r; u <= x + r; ++u) {
                int u1 = u + dirs[d].x, v1 = v + dirs[d].y;
                if (!inside(u, v) || !inside(u1, v1)) continue;
                float a0 = divisorAt(u, v), a1 = divisorAt(u1, v1);
                bool centre = (u == x && v == y) || (u1 == x && v1 == y);
                if (!counts(a, a0, a1, relaxed, centre)) continue;
                float diff = zAt(u, v, a0) - zAt(u1, v1, a1);
                float half_ = 0.5 * diff * diff;
                int i = n++;
                while (i > 0 && halves[i - 1] > half_) {
                    halves[i] = halves[i - 1];
                    --i;
                }
                halves[i] = half_;
            }
        if (n < minPairs) continue;
        float estimate = halves[(n - 1) / 2] / float(NFOR_CHI2_MEDIAN);
        // At least half the pairs equal (most samples exactly 0): the mean sees the rest.
        if (estimate == 0.0 && push.sparse != 0) {
            float sum = 0.0;
            for (int k = 0; k < n; ++k) sum += halves[k];
            estimate = sum / float(n);
        }
        if (best < 0.0 || estimate < best) best = estimate;
    }
    return best;
}

// The window of radius 1 (the default), unrolled: the z and divisors of the pixels its
// pairs read (x - 1..x + 2, y - 2..y + 2), fetched once for both estimates; every array is
// indexed by constants.
float zs[20], as[20];
bool ins[20];

void loadWindow1(int x, int y) {
    [[unroll]] for (int j = 0; j < 5; ++j)
        [[unroll]] for (int i = 0; i < 4; ++i) {
            int u = x - 1 + i, v = y - 2 + j, k = j * 4 + i;
            ins[k] = inside(u, v);
            as[k] = 0.0;
            zs[k] = 0.0;
            if (ins[k]) {
                as[k] = divisorAt(u, v);
                zs[k] = zAt(u, v, as[k]);
            }
        }
}

// Orders s[i] <= s[j] (a compare and two selects).
void exchange(inout float s[9], int i, int j) {
    bool swap = s[i] > s[j];
    float lo = swap ? s[j] : s[i], hi = swap ? s[i] : s[j];
    s[i] = lo;
    s[j] = hi;
}

// s[0..4] the 5 smallest of the 9 values, ascending: a sorting network of 9 inputs without
// the exchanges that reach only its 4 largest outputs.
void sortLowest5(inout float s[9]) {
    exchange(s, 0, 3);
    exchange(s, 1, 7);
    exchange(s, 2, 5);
    exchange(s, 4, 8);
    exchange(s, 0, 7);
    exchange(s, 2, 4);
    exchange(s, 3, 8);
    exchange(s, 5, 6);
    exchange(s, 0, 2);
    exchange(s, 1, 3);
    exchange(s, 4, 5);
    exchange(s, 7, 8);
    exchange(s, 1, 4);
    exchange(s, 3, 6);
    exchange(s, 5, 7);
    exchange(s, 0, 1);
    exchange(s, 2, 4);
    exchange(s, 3, 5);
    exchange(s, 2, 3);
    exchange(s, 4, 5);
    exchange(s, 1, 2);
    exchange(s, 3, 4);
}

// smallestMedian over the window loadWindow1 fetched. A pair that does not count is +inf:
// sorted after the n that do, so the lower median of those is element (n - 1) / 2 < 5 of
// all 9, the same value as the insertion sort's.
float smallestMedian1(float a, bool relaxed, int minPairs) {
    const ivec2 dirs[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
    float best = -1.0, inf = uintBitsToFloat(0x7f800000u);
    [[unroll]] for (int d = 0; d < 4; ++d) {
        float halves[9];
        int n = 0;
        [[unroll]] for (int dv = -1; dv <= 1; ++dv)
            [[unroll]] for (int du = -1; du <= 1; ++du) {
                int k0 = (dv + 2) * 4 + du + 1, k1 = k0 + dirs[d].y * 4 + dirs[d].x;
                bool centre =
                    (du == 0 && dv == 0) || (du + dirs[d].x == 0 && dv + dirs[d].y == 0);
                bool pair = ins[k0] && ins[k1] && counts(a, as[k0], as[k1], relaxed, centre);
                float half_ = inf;
                if (pair) {
                    float diff = zs[k0] - zs[k1];
                    half_ = 0.5 * diff * diff;
                    ++n;
                }
                halves[(dv + 1) * 3 + du + 1] = half_;
            }
        if (n < minPairs) continue;
        // The pairs' sum for the sparse mean, before the network reorders them.
        float sum = 0.0;
        [[unroll]] for (int k = 0; k < 9; ++k) sum += halves[k] < inf ? halves[k] : 0.0;
        sortLowest5(halves);
        float estimate = pickSorted(halves, (n - 1) / 2) / float(NFOR_CHI2_MEDIAN);
        if (estimate == 0.0 && push.sparse != 0) estimate = sum / float(n);
        if (best < 0.0 || estimate < best) best = estimate;
    }
    return best;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    c = int(gl_WorkGroupID.z);
    if (x >= w) return;
    float a = divisorAt(x, y), best;
    bool relax = push.relaxed != 0;
    // Too few neighbours divided alike (an edge pixel's albedo unlike all around it): the
    // differences of its neighbours divided as it is (coverage divides out of colour / albedo).
    if (push.radius == 1) {
        loadWindow1(x, y);
        best = smallestMedian1(a, false, NFOR_NOISE_MIN_PAIRS);
        if (best < 0.0 && relax) best = smallestMedian1(a, true, NFOR_NOISE_MIN_RELAXED_PAIRS);
    } else {
        best = smallestMedian(x, y, a, false, NFOR_NOISE_MIN_PAIRS);
        if (best < 0.0 && relax)
            best = smallestMedian(x, y, a, true, NFOR_NOISE_MIN_RELAXED_PAIRS);
    }
    float scale = a > 0.0 ? a * a : 1.0;
    outputs[(c * h + y) * w + x] = best < 0.0 ? 0.0 : best * push.calibration * scale;
}
