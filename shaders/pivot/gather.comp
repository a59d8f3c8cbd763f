#version 450
#extension GL_GOOGLE_include_directive : require

#include "pivot/gather.h"

layout(local_size_x = PIVOT_LOCAL_SIZE) in;
layout(constant_id = PIVOT_SPEC_NORMALS) const int useNormals = 0;
layout(constant_id = PIVOT_SPEC_IDS) const int useIds = 0;
// Texels a pixel of zsn: 2 with the edge test's inputs, 1 without (pivot/pivot.h).
layout(constant_id = PIVOT_SPEC_ZSN_TEXELS) const int zsnTexels = 2;
layout(binding = PIVOT_GATHER_COLOR) uniform samplerBuffer color;
layout(binding = PIVOT_GATHER_PIVOT) uniform samplerBuffer pivot;
layout(binding = PIVOT_GATHER_ZSN) uniform samplerBuffer zsn;
layout(binding = PIVOT_GATHER_FIT_LO) uniform samplerBuffer fitLo;
layout(binding = PIVOT_GATHER_FIT_HI) uniform samplerBuffer fitHi;
layout(binding = PIVOT_GATHER_GUIDES) uniform samplerBuffer guides;
layout(std430, binding = PIVOT_GATHER_OUT) writeonly buffer Out { float outImage[]; };
layout(binding = PIVOT_GATHER_TILES) uniform samplerBuffer tiles;

int planeSize, gw, gh;

// The near window's places are listed in two 32-bit words.
#if (2 * PIVOT_GATHER_NEAR + 1) * (2 * PIVOT_GATHER_NEAR + 1) > 64
#error "the near window holds more than 64 centres"
#endif

#include "pivot/edge.glsl"
#include "pivot/fitted.glsl"
#include "pivot/guides.glsl"
#include "pivot/lattice.glsl"

// Eqs. 11-12 with t = 1 / w_m = (min(|Z|, |Zm|) / max(|Z|, |Zm|))^8 in [0, 1], which cannot
// overflow: (t Z + Zm) / (t + 1); opposite signs or one zero give t = 0 (Zm).
float combine(float z, float zm) {
    float lo = min(abs(z), abs(zm)), hi = max(abs(z), abs(zm));
    float t;
    if (hi == 0.0)
        t = 1.0;
    else if (z == 0.0 || zm == 0.0 || (z > 0.0) != (zm > 0.0))
        t = 0.0;
    else {
        float r = lo / hi;
        r *= r;
        r *= r;
        t = r * r;
    }
    return (t * z + zm) / (t + 1.0);
}

int x, y, w;
Surface here;
// The pixel's level (3x3 median of z) and its noise (the 3x3 mean of s): a centre across a
// shading edge from it (whose fit left it out) is not gathered.
float hereLevel, hereNoise;
float sumW, sumWz;

// Centre (x0, y0) of radius `radius` on its lattice: its term of eq. 13 at the pixel, when
// its square holds the pixel and it lies on the pixel's side of any shading edge.
void addCentre(int x0, int y0, float radius) {
    int dx = x - x0, dy = y - y0;
    if (float(abs(dx)) > radius || float(abs(dy)) > radius) return;
    int i0 = y0 * w + x0;
    if (zsnTexels == 2 && push.edge > 0.0 &&
        acrossEdge(hereLevel, hereNoise, texelFetch(zsn, 2 * i0).w,
                   texelFetch(zsn, 2 * i0 + 1).x, push.edge))
        return;
    float fdx = float(dx), fdy = float(dy);
    // Each centre stands for step^2 centres of its lattice.
    int step = latticeStep(radius);
    float weight = exp(-(fdx * fdx + fdy * fdy) / (radius * radius)) *
                   gatherTerm(here, surfaceAt(i0)) * float(step * step);
    if (weight == 0.0) return;
    int m = dx >= 0 ? (dy >= 0 ? 0 : 3) : (dy >= 0 ? 1 : 2);
    // The centre's 16 planes as four vec4 texels: square (0..2), quadrant m (3 + 3m ..
    // 5 + 3m), radius (15).
    int texel = 2 * i0;
    vec4 lo0 = texelFetch(fitLo, texel), lo1 = texelFetch(fitLo, texel + 1);
    vec4 hi0 = texelFetch(fitHi, texel), hi1 = texelFetch(fitHi, texel + 1);
    float zs = lo0.x * fdx + lo0.y * fdy + lo0.z;
    vec3 coef = m == 0 ? vec3(lo0.w, lo1.xy)
                       : (m == 1 ? vec3(lo1.zw, hi0.x) : (m == 2 ? hi0.yzw : hi1.xyz));
    float zm = coef.x * fdx + coef.y * fdy + coef.z;
    sumW += weight;
    sumWz += weight * combine(zs, zm);
}

// A centre's radius (-1: no fit), from its planes.
float radiusOf(int i0) {
    return texelFetch(fitHi, 2 * i0 + 1).w;
}

void main() {
    x = int(gl_GlobalInvocationID.x);
    y = push.rowBase + int(gl_WorkGroupID.y);
    int c = push.channel;
    w = push.width;
    int h = push.height;
    if (x >= w) return;
    planeSize = w * h;
    gw = w;
    gh = h;
    int i = y * w + x, at = c * planeSize + i;
    vec4 own = texelFetch(zsn, zsnTexels * i);
    if (own.z < 0.0) {
        outImage[at] = texelFetch(color, at).r;
        return;
    }
    if (zsnTexels == 2) {
        hereLevel = own.w;
        hereNoise = texelFetch(zsn, 2 * i + 1).x;
    }
    sumW = 0.0;
    sumWz = 0.0;
    here = surfaceAt(i);
    // Centres of step 1 (radius <= PIVOT_GATHER_NEAR, dense) directly from the pixel's
    // neighbourhood; the tiles list only the sparser lattices. First the near centres whose
    // squares hold the pixel, as bits in row-major order, then only those, in that order:
    // a SIMD group runs the weights as often as its lanes' largest count of such centres,
    // not once per place of the window.
    const int N = PIVOT_GATHER_NEAR, side = 2 * N + 1;
    uint holds[2] = uint[2](0u, 0u);
    for (int y0 = max(0, y - N); y0 <= min(h - 1, y + N); ++y0)
        for (int x0 = max(0, x - N); x0 <= min(w - 1, x + N); ++x0) {
            float radius = radiusOf(y0 * w + x0);
            if (radius >= 0.0 && radius <= float(N) && float(abs(x - x0)) <= radius &&
                float(abs(y - y0)) <= radius) {
                int bit = (y0 - y + N) * side + (x0 - x + N);
                holds[bit >> 5] |= 1u << (bit & 31);
            }
        }
    for (int word = 0; word < 2; ++word)
        for (uint bits = holds[word]; bits != 0u; bits &= bits - 1u) {
            int bit = word * 32 + findLSB(bits);
            int x0 = x - N + bit % side, y0 = y - N + bit / side;
            addCentre(x0, y0, radiusOf(y0 * w + x0));
        }
    const int T = PIVOT_GATHER_TILE;
    int tileCount = push.tilesX * push.tilesY;
    int orderBase = c * tileCount * T * T, radiusBase = (push.channels + c) * tileCount * T * T;
    // The tile range from the pixel's tile, not the pixel: the same for the invocations of
    // one tile row, which then walk the same centres in step. It spans the tile's local
    // reach: no tile further away lists a square that holds one of its pixels.
    int xt = x / T * T, yt = y / T * T;
    int reach = int(texelFetch(tiles, (2 * push.channels + c) * tileCount * T * T +
                                          (yt / T * push.tilesX + xt / T) * T * T).r);
    if (reach < 0) reach = -2 * T;  // no tile: an empty range
    for (int ty = max(0, yt - reach) / T; ty <= min(h - 1, yt + T - 1 + reach) / T; ++ty)
        for (int tx = max(0, xt - reach) / T; tx <= min(w - 1, xt + T - 1 + reach) / T;
             ++tx) {
            // Chebyshev distance from the pixel to the tile: no square of a smaller radius
            // holds the pixel, and the tile lists its centres by radius, largest first.
            int gapX = max(0, max(tx * T - x, x - (tx * T + T - 1)));
            int gapY = max(0, max(ty * T - y, y - (ty * T + T - 1)));
            float gap = float(max(gapX, gapY));
            int entry = (ty * push.tilesX + tx) * T * T;
            for (int j = 0; j < T * T; ++j) {
                float radius = texelFetch(tiles, radiusBase + entry + j).r;
                if (radius < gap) break;
                int k = int(texelFetch(tiles, orderBase + entry + j).r);
                addCentre(tx * T + k % T, ty * T + k / T, radius);
            }
        }
    // No lattice centre reaches the pixel: its own fit (square and quadrant 0) at its place.
    if (sumW == 0.0 && radiusOf(i) >= 0.0) {
        sumW = 1.0;
        sumWz = combine(texelFetch(fitLo, 2 * i).z, texelFetch(fitLo, 2 * i + 1).y);
    }
    float inputValue = texelFetch(color, at).r;
    outImage[at] =
        sumW > 0.0 ? FilteredValue(texelFetch(pivot, at).r * (sumWz / sumW), inputValue)
                   : inputValue;
}
