#version 450
#extension GL_GOOGLE_include_directive : require

#include "pivot/fit.h"

layout(local_size_x = PIVOT_LOCAL_SIZE) in;
layout(constant_id = PIVOT_SPEC_NORMALS) const int useNormals = 0;
layout(constant_id = PIVOT_SPEC_IDS) const int useIds = 0;
layout(binding = PIVOT_FIT_Z) uniform samplerBuffer zIn;
layout(binding = PIVOT_FIT_S) uniform samplerBuffer sIn;
layout(binding = PIVOT_FIT_NU) uniform samplerBuffer nuIn;
layout(binding = PIVOT_FIT_GUIDES) uniform samplerBuffer guides;
layout(std430, binding = PIVOT_FIT_LO) writeonly buffer FitLo { float fitLo[]; };
layout(std430, binding = PIVOT_FIT_HI) writeonly buffer FitHi { float fitHi[]; };

int planeSize, gw, gh;

#include "pivot/guides.glsl"

// Weighted sums of one fit, coordinates relative to the centre.
struct Moments {
    float s0, sx, sy, sxx, sxy, syy, sz, sxz, syz, sws;
};

struct Plane {
    bool valid;
    float a, b, c;
    float var0;  // predicted variance of the value at the centre
};

Moments zeroMoments() {
    return Moments(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
}

void addSample(inout Moments m, float dx, float dy, float w, float z, float s) {
    float wx = w * dx, wy = w * dy;
    m.s0 += w;
    m.sx += wx;
    m.sy += wy;
    m.sxx += wx * dx;
    m.sxy += wx * dy;
    m.syy += wy * dy;
    m.sz += w * z;
    m.sxz += wx * z;
    m.syz += wy * z;
    m.sws += w * w * s;
}

// The normal equations in (c, a, b) as L D L^T: eliminate c, then a, then b; an unknown
// whose pivot is not above PIVOT_RANK_EPS x its raw second moment is dropped (0), so one
// column, one row or one pixel of data gives a lower-order fit instead of Inf.
Plane solve(Moments m) {
    Plane p = Plane(false, 0.0, 0.0, 0.0, 0.0);
    if (!(m.s0 > 0.0)) return p;
    p.valid = true;
    float l10 = m.sx / m.s0, l20 = m.sy / m.s0;
    float dxx = m.sxx - m.sx * l10, dxy = m.sxy - m.sy * l10, dyy = m.syy - m.sy * l20;
    float rx = m.sxz - m.sz * l10, ry = m.syz - m.sz * l20;
    bool hasA = m.sxx > 0.0 && dxx > PIVOT_RANK_EPS * m.sxx;
    float l21 = hasA ? dxy / dxx : 0.0;
    float dyy2 = dyy - l21 * dxy, ry2 = ry - l21 * rx;
    bool hasB = m.syy > 0.0 && dyy2 > PIVOT_RANK_EPS * m.syy;
    p.b = hasB ? ry2 / dyy2 : 0.0;
    p.a = hasA ? (rx - dxy * p.b) / dxx : 0.0;
    p.c = (m.sz - m.sx * p.a - m.sy * p.b) / m.s0;
    // q^T M^-1 q for q = (1, 0, 0), times sum w^2 s / sum w.
    float u1 = hasA ? -l10 : 0.0;
    float u2 = hasB ? -l20 - l21 * u1 : 0.0;
    float quad = 1.0 / m.s0 + (hasA ? u1 * u1 / dxx : 0.0) + (hasB ? u2 * u2 / dyy2 : 0.0);
    p.var0 = m.sws / m.s0 * quad;
    return p;
}

int x0, y0, w, h, base;
Surface centre;
float goodNu, k;

// Eq. 10's weight of pixel (x, y) for <z> = mean, and the distance term when radius > 0;
// 0 for pixels not fitted.
float weightAt(int x, int y, float mean, float radius, out float z, out float s) {
    int i = y * w + x;
    float nu = texelFetch(nuIn, base + i).r;
    z = texelFetch(zIn, base + i).r;
    s = texelFetch(sIn, base + i).r;
    if (nu < 0.0 || nu > goodNu) return 0.0;
    float geo = geometricTerm(surfaceAt(i), centre);
    if (geo == 0.0) return 0.0;
    float dx = float(x - x0), dy = float(y - y0);
    float e = k * abs(z - mean) / max(abs(mean), PIVOT_TINY) + push.sigmaWeight * nu;
    if (radius > 0.0) e += (dx * dx + dy * dy) / (radius * radius);
    if (e > PIVOT_EXP_CUT) return 0.0;
    return geo * exp(-e);
}

Moments sq, q0, q1, q2, q3;

void addToFits(int x, int y, float wt, float z, float s) {
    if (wt == 0.0) return;
    int dxi = x - x0, dyi = y - y0;
    float dx = float(dxi), dy = float(dyi);
    addSample(sq, dx, dy, wt, z, s);
    if (dxi >= 0 && dyi >= 0) addSample(q0, dx, dy, wt, z, s);
    if (dxi <= 0 && dyi >= 0) addSample(q1, dx, dy, wt, z, s);
    if (dxi <= 0 && dyi <= 0) addSample(q2, dx, dy, wt, z, s);
    if (dxi >= 0 && dyi <= 0) addSample(q3, dx, dy, wt, z, s);
}

// |Z(centre) - Zm(centre)| beyond the limit plus twice the quadrant's predicted std.
bool disagrees(Plane square, Plane quadrant) {
    if (!quadrant.valid) return false;
    float allowed = push.disagreement * abs(square.c) + 2.0 * sqrt(quadrant.var0);
    return abs(square.c - quadrant.c) > allowed;
}

void storePlane(int index, int c, int at, float value) {
    int plane = index < PIVOT_PLANES_PER_BUFFER ? index : index - PIVOT_PLANES_PER_BUFFER;
    int offset = (plane * push.channels + c) * planeSize + at;
    if (index < PIVOT_PLANES_PER_BUFFER)
        fitLo[offset] = value;
    else
        fitHi[offset] = value;
}

void storeFit(int index, int c, int at, Plane p, Plane square) {
    if (!p.valid) p = square;
    storePlane(3 * index, c, at, p.a);
    storePlane(3 * index + 1, c, at, p.b);
    storePlane(3 * index + 2, c, at, p.c);
}

// A centre without a fit: zero planes, radius -1.
void storeNone(int c, int at) {
    for (int i = 0; i < 15; ++i) storePlane(i, c, at, 0.0);
    storePlane(15, c, at, -1.0);
}

void main() {
    x0 = int(gl_GlobalInvocationID.x);
    y0 = push.rowBase + int(gl_WorkGroupID.y);
    int c = int(gl_WorkGroupID.z);
    w = push.width;
    h = push.height;
    if (x0 >= w) return;
    planeSize = w * h;
    gw = w;
    gh = h;
    base = c * planeSize;
    goodNu = push.goodNu;
    k = push.k;
    int at = y0 * w + x0;
    centre = surfaceAt(at);
    if (texelFetch(nuIn, base + at).r < 0.0) {
        storeNone(c, at);
        return;
    }

    // <z> during growth: the centre's mean z over its valid 3x3 neighbours.
    float zc = 0.0;
    int n = 0;
    for (int v = max(0, y0 - 1); v <= min(h - 1, y0 + 1); ++v)
        for (int u = max(0, x0 - 1); u <= min(w - 1, x0 + 1); ++u)
            if (texelFetch(nuIn, base + v * w + u).r >= 0.0) {
                zc += texelFetch(zIn, base + v * w + u).r;
                ++n;
            }
    zc /= float(n);

    // Section 4.3: add ring r to the sums; from r = 2 (5x5) check the stop criteria.
    sq = zeroMoments();
    q0 = sq;
    q1 = sq;
    q2 = sq;
    q3 = sq;
    int radius = 2;
    // The sum and count of z over the fitted pixels of the squares of radius r and r - 1:
    // the chosen square's mean below, without another pass over it.
    float sumZ = 0.0, sumZBefore = 0.0;
    int fitted = 0, fittedBefore = 0;
    for (int r = 0;; ++r) {
        sumZBefore = sumZ;
        fittedBefore = fitted;
        for (int y = max(0, y0 - r); y <= min(h - 1, y0 + r); ++y) {
            bool edge = abs(y - y0) == r;
            int step = edge ? 1 : 2 * r;
            for (int x = x0 - r; x <= x0 + r; x += step) {
                if (x < 0 || x >= w) continue;
                float z, s;
                float wt = weightAt(x, y, zc, 0.0, z, s);
                addToFits(x, y, wt, z, s);
                if (wt > 0.0) {
                    sumZ += z;
                    ++fitted;
                }
            }
        }
        if (r < 2) continue;
        Plane square = solve(sq);
        if (square.valid &&
            (disagrees(square, solve(q0)) || disagrees(square, solve(q1)) ||
             disagrees(square, solve(q2)) || disagrees(square, solve(q3)))) {
            radius = max(2, r - 1);
            if (radius < r) {
                sumZ = sumZBefore;
                fitted = fittedBefore;
            }
            break;
        }
        bool quiet = square.valid && sqrt(square.var0) <= push.targetNoise * abs(square.c);
        bool covers = x0 - r <= 0 && y0 - r <= 0 && x0 + r >= w - 1 && y0 + r >= h - 1;
        if (quiet || covers || r >= push.maxRadius) {
            radius = r;
            break;
        }
    }

    // The chosen square, fitted with eq. 10 in full: <z> is the mean z of its fitted pixels.
    int y0r = max(0, y0 - radius), y1r = min(h - 1, y0 + radius);
    int x0r = max(0, x0 - radius), x1r = min(w - 1, x0 + radius);
    float mean = sumZ / float(max(fitted, 1));
    sq = zeroMoments();
    q0 = sq;
    q1 = sq;
    q2 = sq;
    q3 = sq;
    float fr = float(radius);
    for (int y = y0r; y <= y1r; ++y)
        for (int x = x0r; x <= x1r; ++x) {
            float z, s;
            float wt = weightAt(x, y, mean, fr, z, s);
            addToFits(x, y, wt, z, s);
        }
    Plane square = solve(sq);
    if (!square.valid) {
        storeNone(c, at);
        return;
    }
    storeFit(0, c, at, square, square);
    storeFit(1, c, at, solve(q0), square);
    storeFit(2, c, at, solve(q1), square);
    storeFit(3, c, at, solve(q2), square);
    storeFit(4, c, at, solve(q3), square);
    storePlane(15, c, at, fr);
}
