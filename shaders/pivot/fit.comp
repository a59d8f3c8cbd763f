#version 450
#extension GL_GOOGLE_include_directive : require

#include "pivot/fit.h"

layout(local_size_x = PIVOT_LOCAL_SIZE) in;
layout(constant_id = PIVOT_SPEC_NORMALS) const int useNormals = 0;
layout(constant_id = PIVOT_SPEC_IDS) const int useIds = 0;
// Texels a pixel of zsn: 2 with the edge test's inputs, 1 without (pivot/pivot.h).
layout(constant_id = PIVOT_SPEC_ZSN_TEXELS) const int zsnTexels = 2;
// This dispatch's channel's (z, s, nu, level) (level: the median of z over the valid 3x3
// neighbours; 0 where zsnTexels is 1), then its noise where zsnTexels is 2.
layout(binding = PIVOT_FIT_ZSN) uniform samplerBuffer zsn;
layout(binding = PIVOT_FIT_GUIDES) uniform samplerBuffer guides;
// A centre's 8 planes of each buffer as two vec4s (pivot/pivot.h): four writes a centre.
layout(std430, binding = PIVOT_FIT_LO) writeonly buffer FitLo { vec4 fitLo[]; };
layout(std430, binding = PIVOT_FIT_HI) writeonly buffer FitHi { vec4 fitHi[]; };

int planeSize, gw, gh;

#include "pivot/edge.glsl"
#include "pivot/guides.glsl"
#include "pivot/lattice.glsl"

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

int x0, y0, w, h;
Surface centre;
// The centre's level (3x3 median of z) and its noise (3x3 mean of s): the edge test's side.
float centreLevel, centreNoise;
float goodNu, k;

// Eq. 10's weight of pixel (x, y) for <z> = mean, and the distance term when radius > 0;
// 0 for pixels not fitted and, in the final fit (radius > 0), for those across a shading
// edge from the centre.
float weightAt(int x, int y, float mean, float radius, out float z, out float s) {
    int i = y * w + x;
    vec4 pixel = texelFetch(zsn, zsnTexels * i);
    float nu = pixel.z;
    z = pixel.x;
    s = pixel.y;
    if (nu < 0.0 || nu > goodNu) return 0.0;
    if (zsnTexels == 2 && radius > 0.0 && push.edge > 0.0 &&
        acrossEdge(pixel.w, texelFetch(zsn, 2 * i + 1).x, centreLevel, centreNoise, push.edge))
        return 0.0;
    float geo = dataTerm(surfaceAt(i), centre);
    if (geo == 0.0) return 0.0;
    float dx = float(x - x0), dy = float(y - y0);
    float e = k * abs(z - mean) / max(abs(mean), PIVOT_TINY) + push.sigmaWeight * nu;
    if (radius > 0.0) e += (dx * dx + dy * dy) / (radius * radius);
    if (e > PIVOT_EXP_CUT) return 0.0;
    return geo * exp(-e);
}

// The window as nine disjoint parts, so that each pixel is added to one set of sums: the
// open quadrants (dx, dy != 0), the four half-axes and the centre. A quadrant of eq. 11
// (axes included) and the square are sums of parts (quadrantSums, squareSums). The window
// is walked in segments of one part each: no per-pixel test of which fits a pixel joins.
Moments open0, open1, open2, open3;     // dx > 0, dy > 0; dx < 0, dy > 0; ...; dx > 0, dy < 0
Moments axisXp, axisXm, axisYp, axisYm;  // dy = 0 and dx > 0, dx < 0; dx = 0 and dy > 0, < 0
Moments middle;                          // dx = dy = 0
// The sum and count of z over the fitted pixels added so far (<z> of the final fit).
float sumZ;
int fitted;

Moments plus(Moments a, Moments b) {
    return Moments(a.s0 + b.s0, a.sx + b.sx, a.sy + b.sy, a.sxx + b.sxx, a.sxy + b.sxy,
                   a.syy + b.syy, a.sz + b.sz, a.sxz + b.sxz, a.syz + b.syz, a.sws + b.sws);
}

void clearParts() {
    open0 = zeroMoments();
    open1 = open0;
    open2 = open0;
    open3 = open0;
    axisXp = open0;
    axisXm = open0;
    axisYp = open0;
    axisYm = open0;
    middle = open0;
}

// Quadrant m of eq. 11 (0: dx >= 0, dy >= 0; 1: dx <= 0, dy >= 0; 2: dx <= 0, dy <= 0; 3:
// dx >= 0, dy <= 0), its half-axes and the centre included.
Moments quadrantSums(int m) {
    if (m == 0) return plus(plus(open0, axisXp), plus(axisYp, middle));
    if (m == 1) return plus(plus(open1, axisXm), plus(axisYp, middle));
    if (m == 2) return plus(plus(open2, axisXm), plus(axisYm, middle));
    return plus(plus(open3, axisXp), plus(axisYm, middle));
}

Moments squareSums() {
    return plus(plus(plus(plus(open0, open1), plus(open2, open3)),
                     plus(plus(axisXp, axisXm), plus(axisYp, axisYm))),
                middle);
}

// The sums of row y's pixels xa..xb (clipped to the image) with eq. 10's weight.
Moments rowSums(int y, int xa, int xb, float mean, float radius) {
    Moments m = zeroMoments();
    if (y < 0 || y >= h) return m;
    float dy = float(y - y0);
    for (int x = max(xa, 0); x <= min(xb, w - 1); ++x) {
        float z, s;
        float wt = weightAt(x, y, mean, radius, z, s);
        if (wt == 0.0) continue;
        addSample(m, float(x - x0), dy, wt, z, s);
        sumZ += z;
        ++fitted;
    }
    return m;
}

// The same for column x's pixels ya..yb.
Moments columnSums(int x, int ya, int yb, float mean, float radius) {
    Moments m = zeroMoments();
    if (x < 0 || x >= w) return m;
    float dx = float(x - x0);
    for (int y = max(ya, 0); y <= min(yb, h - 1); ++y) {
        float z, s;
        float wt = weightAt(x, y, mean, radius, z, s);
        if (wt == 0.0) continue;
        addSample(m, dx, float(y - y0), wt, z, s);
        sumZ += z;
        ++fitted;
    }
    return m;
}

// Ring r of the square (r = 0: the centre) into the parts, growth's weight (<z> = mean, no
// distance term).
void addRing(int r, float mean) {
    if (r == 0) {
        middle = plus(middle, rowSums(y0, x0, x0, mean, 0.0));
        return;
    }
    open2 = plus(open2, rowSums(y0 - r, x0 - r, x0 - 1, mean, 0.0));
    axisYm = plus(axisYm, rowSums(y0 - r, x0, x0, mean, 0.0));
    open3 = plus(open3, rowSums(y0 - r, x0 + 1, x0 + r, mean, 0.0));
    open1 = plus(open1, rowSums(y0 + r, x0 - r, x0 - 1, mean, 0.0));
    axisYp = plus(axisYp, rowSums(y0 + r, x0, x0, mean, 0.0));
    open0 = plus(open0, rowSums(y0 + r, x0 + 1, x0 + r, mean, 0.0));
    open2 = plus(open2, columnSums(x0 - r, y0 - r + 1, y0 - 1, mean, 0.0));
    axisXm = plus(axisXm, columnSums(x0 - r, y0, y0, mean, 0.0));
    open1 = plus(open1, columnSums(x0 - r, y0 + 1, y0 + r - 1, mean, 0.0));
    open3 = plus(open3, columnSums(x0 + r, y0 - r + 1, y0 - 1, mean, 0.0));
    axisXp = plus(axisXp, columnSums(x0 + r, y0, y0, mean, 0.0));
    open0 = plus(open0, columnSums(x0 + r, y0 + 1, y0 + r - 1, mean, 0.0));
}

// |Z(centre) - Zm(centre)| beyond the limit plus twice the quadrant's predicted std.
bool disagrees(Plane square, Plane quadrant) {
    if (!quadrant.valid) return false;
    float allowed = push.disagreement * abs(square.c) + 2.0 * sqrt(quadrant.var0);
    return abs(square.c - quadrant.c) > allowed;
}

// The planes of the centre `at` (in the bound buffers of its channel): the square's,
// quadrant m's (the square's where a quadrant has no fit) and the radius, as four vec4
// writes.
void storeFits(int at, Plane square, float radius) {
    Plane q[4];
    for (int m = 0; m < 4; ++m) {
        q[m] = solve(quadrantSums(m));
        if (!q[m].valid) q[m] = square;
    }
    int texel = 2 * at;
    fitLo[texel] = vec4(square.a, square.b, square.c, q[0].a);
    fitLo[texel + 1] = vec4(q[0].b, q[0].c, q[1].a, q[1].b);
    fitHi[texel] = vec4(q[1].c, q[2].a, q[2].b, q[2].c);
    fitHi[texel + 1] = vec4(q[3].a, q[3].b, q[3].c, radius);
}

// A centre without a fit: zero planes, radius -1.
void storeNone(int at) {
    int texel = 2 * at;
    fitLo[texel] = vec4(0.0);
    fitLo[texel + 1] = vec4(0.0);
    fitHi[texel] = vec4(0.0);
    fitHi[texel + 1] = vec4(0.0, 0.0, 0.0, -1.0);
}

// Section 4.3 for the centre (x0, y0): the radius the square grows to from 5x5, and the
// mean z of the fitted pixels of that square (<z> of the final fit). A centre whose radius
// leaves its lattice (eq. 13's quadrature) stops there, stores that square's growth fits
// and returns -1: it needs no final fit.
int grow(out float mean) {
    // <z> during growth: the centre's mean z over its valid 3x3 neighbours.
    float zc = 0.0;
    int n = 0;
    for (int v = max(0, y0 - 1); v <= min(h - 1, y0 + 1); ++v)
        for (int u = max(0, x0 - 1); u <= min(w - 1, x0 + 1); ++u)
            if (texelFetch(zsn, zsnTexels * (v * w + u)).z >= 0.0) {
                zc += texelFetch(zsn, zsnTexels * (v * w + u)).x;
                ++n;
            }
    zc /= float(n);

    // Add ring r to the sums; from r = 2 (5x5) check the stop criteria.
    clearParts();
    int radius = 2;
    // The sum and count of z over the fitted pixels of the squares of radius r and r - 1:
    // the chosen square's mean, without another pass over it.
    sumZ = 0.0;
    fitted = 0;
    float sumZBefore = 0.0;
    int fittedBefore = 0;
    for (int r = 0;; ++r) {
        sumZBefore = sumZ;
        fittedBefore = fitted;
        addRing(r, zc);
        if (r < 2) continue;
        Plane square = solve(squareSums());
        if (square.valid && (disagrees(square, solve(quadrantSums(0))) ||
                             disagrees(square, solve(quadrantSums(1))) ||
                             disagrees(square, solve(quadrantSums(2))) ||
                             disagrees(square, solve(quadrantSums(3))))) {
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
        // Growing on would leave the lattice: stop here, off it, with this square's growth
        // fits and the radius r + 1 (off the lattice, as the gather tests it).
        if (!onLattice(x0, y0, float(r + 1))) {
            int at = y0 * w + x0;
            if (!square.valid) {
                storeNone(at);
                return -1;
            }
            storeFits(at, square, float(r + 1));
            return -1;
        }
    }
    mean = sumZ / float(max(fitted, 1));
    return radius;
}

// The chosen square of the centre (x0, y0) fitted with eq. 10 in full, row by row (a row's
// three segments go to the parts its sign of dy selects), and stored.
void fitAndStore(int radius, float mean) {
    int at = y0 * w + x0;
    clearParts();
    float fr = float(radius);
    for (int y = max(0, y0 - radius); y <= min(h - 1, y0 + radius); ++y) {
        Moments left = rowSums(y, x0 - radius, x0 - 1, mean, fr);
        Moments mid = rowSums(y, x0, x0, mean, fr);
        Moments right = rowSums(y, x0 + 1, x0 + radius, mean, fr);
        if (y < y0) {
            open2 = plus(open2, left);
            axisYm = plus(axisYm, mid);
            open3 = plus(open3, right);
        } else if (y > y0) {
            open1 = plus(open1, left);
            axisYp = plus(axisYp, mid);
            open0 = plus(open0, right);
        } else {
            axisXm = left;
            middle = mid;
            axisXp = right;
        }
    }
    Plane square = solve(squareSums());
    if (!square.valid) {
        storeNone(at);
        return;
    }
    storeFits(at, square, fr);
}

// The workgroup's centres (one row segment) after growth: radius (-1: no fit to make) and
// <z>; then, by rank of radius, which centre each invocation fits.
shared int grownRadius[PIVOT_LOCAL_SIZE];
shared float grownMean[PIVOT_LOCAL_SIZE];
shared int fitOrder[PIVOT_LOCAL_SIZE];

// The column (offset in the workgroup's row segment) of invocation i's centre during growth.
// Growth stops where a centre leaves its lattice, at a radius set by the largest power of
// two dividing x0 (and y0): columns are grouped by it (0 mod 8, 4 mod 8, 2 mod 4, odd) so
// that a SIMD group's centres grow alike, instead of one lane in eight growing to the
// largest square while the others wait.
#if PIVOT_LOCAL_SIZE != 64
#error "the column order below is written for 64 invocations"
#endif
int columnOf(int i) {
    if (i < 8) return i * 8;
    if (i < 16) return (i - 8) * 8 + 4;
    if (i < 32) return (i - 16) * 4 + 2;
    return (i - 32) * 2 + 1;
}

void main() {
    int local = int(gl_LocalInvocationID.x);
    int groupX = int(gl_WorkGroupID.x) * PIVOT_LOCAL_SIZE;
    x0 = groupX + columnOf(local);
    y0 = push.rowBase + int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    planeSize = w * h;
    gw = w;
    gh = h;
    goodNu = push.goodNu;
    k = push.k;
    // Growth, one centre per invocation. Every invocation reaches the barriers below.
    int radius = -1;
    float mean = 0.0;
    if (x0 < w) {
        int at = y0 * w + x0;
        centre = surfaceAt(at);
        // A pixel beside other ids is data to its side's fits but no centre: its square,
        // mostly of other ids, would grow far on few pixels of its own.
        if (texelFetch(zsn, zsnTexels * at).z < 0.0 || boundaryTerm(x0, y0) == 0.0)
            storeNone(at);
        else
            radius = grow(mean);
    }
    grownRadius[local] = radius;
    grownMean[local] = mean;
    memoryBarrierShared();
    barrier();
    // The final fits cost (2R + 1)^2 each and invocations run in SIMD groups that take as
    // long as their largest square: invocation i fits the centre of rank i by radius (ties
    // by invocation), so that each group's squares are alike.
    int rank = 0;
    for (int j = 0; j < PIVOT_LOCAL_SIZE; ++j) {
        int other = grownRadius[j];
        if (other > radius || (other == radius && j < local)) ++rank;
    }
    fitOrder[rank] = local;
    memoryBarrierShared();
    barrier();
    int mine = fitOrder[local];
    radius = grownRadius[mine];
    if (radius < 0) return;
    x0 = groupX + columnOf(mine);
    centre = surfaceAt(y0 * w + x0);
    // The edge test's side of the centre (growth does not test; the final fit does).
    if (zsnTexels == 2) {
        centreLevel = texelFetch(zsn, 2 * (y0 * w + x0)).w;
        centreNoise = texelFetch(zsn, 2 * (y0 * w + x0) + 1).x;
    }
    fitAndStore(radius, grownMean[mine]);
}
