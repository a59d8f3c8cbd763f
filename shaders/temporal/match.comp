#version 450
#extension GL_GOOGLE_include_directive : require

#include "temporal/match.h"

layout(local_size_x = TEMPORAL_LOCAL_SIZE) in;
layout(std430, binding = TEMPORAL_MATCH_PREVIOUS) readonly buffer Previous { float previous[]; };
layout(std430, binding = TEMPORAL_MATCH_POSITION) readonly buffer Position { float position[]; };
layout(std430, binding = TEMPORAL_MATCH_CURRENT) readonly buffer Current { float current[]; };
layout(std430, binding = TEMPORAL_MATCH_FEATURES) readonly buffer Features { float features[]; };
layout(std430, binding = TEMPORAL_MATCH_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = TEMPORAL_MATCH_SPP) readonly buffer Spp { float spp[]; };
layout(std430, binding = TEMPORAL_MATCH_MOTION) readonly buffer Motion { float motion[]; };
layout(std430, binding = TEMPORAL_MATCH_WEIGHT) writeonly buffer Weight { float weight[]; };
layout(std430, binding = TEMPORAL_MATCH_NEXT) writeonly buffer Next { float next[]; };

int n;  // pixels per plane

bool finite(float v) {
    return !(isnan(v) || isinf(v));
}

// Plane k of t's features at pixel i, and of j's at pixel k.
float cur(int plane, int i) {
    return current[plane * n + i];
}
float nb(int plane, int k) {
    return features[plane * n + k];
}

// Whether the features present in both frames agree between t's pixel i and j's pixel k.
// Every comparison is written to fail on NaN.
bool featuresAgree(int i, int k) {
    int has = push.features;
    if ((has & TEMPORAL_HAS_ID) != 0 && !(cur(TEMPORAL_FEATURE_ID, i) == nb(TEMPORAL_FEATURE_ID, k)))
        return false;
    if ((has & TEMPORAL_HAS_NORMAL) != 0) {
        vec3 a = vec3(cur(0, i), cur(1, i), cur(2, i));
        vec3 b = vec3(nb(0, k), nb(1, k), nb(2, k));
        float la = dot(a, a), lb = dot(b, b);
        bool bothZero = la == 0.0 && lb == 0.0;
        if (!bothZero && !(dot(a, b) >= push.normalCos * sqrt(la * lb))) return false;
    }
    if ((has & TEMPORAL_HAS_DEPTH) != 0) {
        float a = cur(TEMPORAL_FEATURE_DEPTH, i), b = nb(TEMPORAL_FEATURE_DEPTH, k);
        if (!(a == b) && !(finite(a - b) && abs(a - b) <= push.depthRel * max(abs(a), abs(b))))
            return false;
    }
    if ((has & TEMPORAL_HAS_ALBEDO) != 0)
        for (int c = 0; c < 3; ++c) {
            float a = cur(TEMPORAL_FEATURE_ALBEDO + c, i), b = nb(TEMPORAL_FEATURE_ALBEDO + c, k);
            float scale = max(max(abs(a), abs(b)), float(TEMPORAL_ALBEDO_FLOOR));
            if (!(a == b) && !(finite(a - b) && abs(a - b) <= push.albedoRel * scale)) return false;
        }
    return true;
}

// j's motion at pixel k towards the frame one step in direction `d`, in positions (y down).
vec2 step(int k, int d) {
    if (d < 0) return vec2(motion[k], -motion[n + k]);
    return vec2(-motion[2 * n + k], motion[3 * n + k]);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    if (x >= w) return;
    n = w * h;
    int i = y * w + x;
    float nan = uintBitsToFloat(0x7fc00000u);
    bool self = (push.flags & TEMPORAL_MATCH_SELF) != 0;
    bool withMotion = (push.flags & TEMPORAL_MATCH_WITH_MOTION) != 0;
    vec2 centre = vec2(float(x) + 0.5, float(y) + 0.5);
    vec2 p = self ? centre : vec2(position[i], position[n + i]);

    bool geometry = finite(p.x) && finite(p.y) && p.x >= 0.0 && p.y >= 0.0 &&
                    p.x < float(w) && p.y < float(h);
    int k = 0;
    if (geometry) {
        k = int(floor(p.y)) * w + int(floor(p.x));
        if (!self) geometry = featuresAgree(i, k);
    }
    if (geometry && !self && withMotion && push.motionTol > 0.0) {
        vec2 from = (push.flags & TEMPORAL_MATCH_FIRST) != 0 ? centre
                                                              : vec2(previous[i], previous[n + i]);
        vec2 back = p + step(k, -push.direction);
        vec2 miss = abs(back - from);
        geometry = miss.x <= push.motionTol && miss.y <= push.motionTol;
    }
    bool colour = geometry;
    for (int c = 0; c < push.colorChannels && colour; ++c) colour = finite(color[c * n + k]);

    float wt = 0.0;
    if (colour) {
        wt = 1.0;
        if ((push.flags & TEMPORAL_MATCH_WITH_SPP) != 0) {
            float s = spp[k];
            if (finite(s) && s > 0.0) wt = s;
        }
    }
    weight[i] = wt;
    vec2 onward = p;
    if (withMotion) onward = geometry ? p + step(k, push.direction) : vec2(nan);
    next[i] = onward.x;
    next[n + i] = onward.y;
}
