#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "nfor/clamp.h"
#include "nfor/sorted.glsl"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(std430, binding = NFOR_CLAMP_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_CLAMP_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = NFOR_CLAMP_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = NFOR_CLAMP_OUT) writeonly buffer Out { float outColor[]; };
layout(std430, binding = NFOR_CLAMP_MASK) writeonly buffer Mask { float mask[]; };

int w, h;

bool emitterAt(int x, int y) {
    float most = 0.0;
    for (int k = 0; k < push.albedoChannels; ++k) most = max(most, albedo[(k * h + y) * w + x]);
    return most > push.emitterAlbedo;
}

// The divisor of channel c at (x, y): the albedo's channel above the floor, else 0 (not
// divided).
float divisorAt(int c, int x, int y) {
    if (push.albedoChannels == 0) return 0.0;
    float a = albedo[(min(c, push.albedoChannels - 1) * h + y) * w + x];
    return a > float(NFOR_NOISE_ALBEDO_FLOOR) ? a : 0.0;
}

// Index of the neighbour compared with in `count` sorted ascending.
int rankIndex(int count) {
    return push.rank > 0 ? max(0, count - push.rank) : (count - 1) / 2;
}

// Whether divisors a and b divide alike: both not, or both within the ratio.
bool alike(float a, float b) {
    float ratio = float(NFOR_NOISE_DIVISOR_RATIO);
    if (a == 0.0 || b == 0.0) return a == b;
    return a <= b * ratio && b <= a * ratio;
}

// Channel c of (x, y) clamped on its own: its value, or its limit where above it.
float clampedAt(int c, int x, int y) {
    int at = (c * h + y) * w + x;
    float value = color[at];
    // The z of the neighbours divided like this pixel, sorted as they come; with none, the
    // neighbours' colours (a lone pixel whose albedo is unlike all around it).
    float a = divisorAt(c, x, y);
    float z[9], raw[9];  // the 8 neighbours, in sorted.glsl's 9 slots
    int n = 0, m = 0;
    bool emitterNear = false;
    [[unroll]] for (int dv = -1; dv <= 1; ++dv)
        [[unroll]] for (int du = -1; du <= 1; ++du) {
            int u = x + du, v = y + dv;
            if ((du == 0 && dv == 0) || u < 0 || v < 0 || u >= w || v >= h) continue;
            emitterNear = emitterNear || emitterAt(u, v);
            float cq = color[(c * h + v) * w + u], aq = divisorAt(c, u, v);
            insertSorted(raw, m, cq);
            ++m;
            if (!alike(a, aq)) continue;
            insertSorted(z, n, aq > 0.0 ? cq / aq : cq);
            ++n;
        }
    // Unlike all around it next to a light: the light's edge, kept or clamped on its own terms.
    bool edge = n == 0 && emitterNear;
    if (m == 0 || (edge && push.lightEdge < 0.0)) return value;
    float s = n > 0 && a > 0.0 ? a : 1.0;
    float median = n > 0 ? pickSorted(z, rankIndex(n)) : pickSorted(raw, rankIndex(m));
    float relative = edge ? push.lightEdge : push.relative;
    float limit = median + push.threshold * sqrt(variance[at]) / s + relative * abs(median);
    return value / s > limit ? limit * s : value;
}

// The sum of (x, y)'s channels' positive parts (compared with each other: a negative
// channel must not make a firefly look dim); 0 outside the frame.
float brightnessAt(int x, int y) {
    if (x < 0 || y < 0 || x >= w || y >= h) return 0.0;
    float sum = 0.0;
    for (int k = 0; k < push.channels; ++k) sum += max(color[(k * h + y) * w + x], 0.0);
    return sum;
}

// The brightness of (x, y)'s line: over the axes and the diagonals, the largest of the
// dimmer side's brightest pixel within 2 steps.
float lineSupport(int x, int y) {
    const ivec2 directions[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(-1, 1));
    float support = 0.0;
    for (int i = 0; i < 4; ++i) {
        ivec2 d = directions[i];
        float ahead =
            max(brightnessAt(x + d.x, y + d.y), brightnessAt(x + 2 * d.x, y + 2 * d.y));
        float behind =
            max(brightnessAt(x - d.x, y - d.y), brightnessAt(x - 2 * d.x, y - 2 * d.y));
        support = max(support, min(ahead, behind));
    }
    return support;
}

// Whether a pixel of albedo above NFOR_LINE_FLOOR_LIGHT (a bright emitter) lies within
// NFOR_LINE_FLOOR_REACH pixels of (x, y), itself included.
bool emitterWithinReach(int x, int y) {
    int r = NFOR_LINE_FLOOR_REACH;
    for (int v = max(y - r, 0); v <= min(y + r, h - 1); ++v)
        for (int u = max(x - r, 0); u <= min(x + r, w - 1); ++u)
            for (int k = 0; k < push.albedoChannels; ++k)
                if (albedo[(k * h + v) * w + u] > float(NFOR_LINE_FLOOR_LIGHT)) return true;
    return false;
}

// Whether (x, y) is a lone light seen directly: an emitter of albedo push.loneLight or
// more, no emitter among its neighbours, each channel's colour within the ratio of its
// albedo.
bool loneLightAt(int x, int y) {
    if (push.loneLight <= 0.0 || !emitterAt(x, y)) return false;
    for (int v = y - 1; v <= y + 1; ++v)
        for (int u = x - 1; u <= x + 1; ++u)
            if ((u != x || v != y) && u >= 0 && v >= 0 && u < w && v < h && emitterAt(u, v))
                return false;
    float most = 0.0, ratio = float(NFOR_LONE_LIGHT_RATIO);
    for (int k = 0; k < push.channels; ++k) {
        float a = albedo[(min(k, push.albedoChannels - 1) * h + y) * w + x];
        float value = color[(k * h + y) * w + x];
        if (!(a > 0.0 && value <= a * ratio && a <= value * ratio)) return false;
        most = max(most, a);
    }
    return most >= push.loneLight;
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    if (x >= w) return;
    mask[y * w + x] = emitterAt(x, y) ? 0.0 : 1.0;
    // Every channel of the pixel here: the channels' blend reads them all. Arrays indexed by
    // constants only (the loops unrolled to the largest count), so they stay in registers.
    float values[NFOR_MAX_CHANNELS];
    [[unroll]] for (int c = 0; c < NFOR_MAX_CHANNELS; ++c)
        if (c < push.channels) {
            values[c] = color[(c * h + y) * w + x];
            outColor[(c * h + y) * w + x] = values[c];
        }
    if (push.threshold <= 0.0) return;
    // A line's pixel (a highlight's streak) keeps its values; with the floor on, a line's
    // peak keeps at least lineFloor x its line's brightness, its hue kept.
    float brightness = brightnessAt(x, y);
    float support = push.line > 0.0 || push.lineFloor > 0.0 ? lineSupport(x, y) : 0.0;
    if (push.line > 0.0 && support > push.line * brightness) return;
    float floorShare = brightness > 0.0 ? min(push.lineFloor * support / brightness, 1.0) : 0.0;
    // A light smaller than a pixel seen directly keeps its values.
    if (loneLightAt(x, y)) return;
    float own[NFOR_MAX_CHANNELS];
    [[unroll]] for (int c = 0; c < NFOR_MAX_CHANNELS; ++c)
        if (c < push.channels) own[c] = clampedAt(c, x, y);
    // The share t = 1 - (the second smallest of clamped / value over the channels) of the
    // pixel scaled as a whole by the clamped channels' sum over the values' sum.
    float sum = 0.0, kept = 0.0, least = 1.0, second = 1.0;
    [[unroll]] for (int c = 0; c < NFOR_MAX_CHANNELS; ++c)
        if (c < push.channels) {
            sum += values[c];
            kept += own[c];
            float ratio = values[c] > 0.0 ? own[c] / values[c] : 1.0;
            second = min(second, max(least, ratio));
            least = min(least, ratio);
        }
    float t = clamp(1.0 - second, 0.0, 1.0);
    // The floor raises only a value below it: the emitters' window is read only then, once.
    bool reachRead = false, reach = false;
    [[unroll]] for (int c = 0; c < NFOR_MAX_CHANNELS; ++c)
        if (c < push.channels) {
            float value = values[c], result = own[c];
            if (push.sumChannels != 0) {
                float whole = sum > 0.0 ? value * min(kept / sum, 1.0) : value;
                if (t > 0.0) result = (1.0 - t) * own[c] + t * whole;
            }
            float floorValue = floorShare * value;
            if (push.lineFloor > 0.0 && value > 0.0 && !(result > floorValue)) {
                if (!reachRead) reach = emitterWithinReach(x, y);
                reachRead = true;
                if (reach) result = max(result, floorValue);
            }
            outColor[(c * h + y) * w + x] = result;
        }
}
