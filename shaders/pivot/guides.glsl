// The geometric terms of the pivot filter (section 4.4), for kernels that declare the
// vec4 texel buffer `guides` (per pixel one texel, PivotGuideBuffer: the normal, of length at
// most 1, zero where the normal is zero, and a label of the pixel's object and part ids, 1 +
// the index of the pair among the frame's distinct pairs, negated where the normal is zero), the
// specialization constants useNormals / useIds and the ints `planeSize` (width x height) and
// `gw`, `gh` (width, height).

// Pixel i's guides: one fetch.
vec4 GuideAt(int i) {
    return texelFetch(guides, i);
}

// 0 across object boundaries and between parts: the ids differ (so do the labels' sizes).
float idTerm(int i, int i0) {
    if (useIds == 0) return 1.0;
    return abs(GuideAt(i).w) == abs(GuideAt(i0).w) ? 1.0 : 0.0;
}

// A pixel's guides, read once where one side of many comparisons stays the same.
struct Surface {
    vec4 g;  // GuideAt
};

Surface surfaceAt(int i) {
    Surface s = Surface(vec4(0.0));
    if (useNormals != 0 || useIds != 0) s.g = GuideAt(i);
    return s;
}

// The normal term d^4 for d = cos(n, n0) > 1/2, else 0 (normals of length at most 1), times
// coverage^4; two zero normals (both labels negative) give 1, one gives 0; times the id
// terms.
float geometricTerm(Surface s, Surface s0, float coverage) {
    float normal = 1.0;
    if (useNormals != 0 && (s.g.w >= 0.0 || s0.g.w >= 0.0)) {
        float d = s.g.w < 0.0 || s0.g.w < 0.0
                      ? 0.0
                      : dot(s.g.xyz, s0.g.xyz) / (length(s.g.xyz) * length(s0.g.xyz));
        float c2 = coverage * coverage;
        normal = d > 0.5 ? d * d * d * d * (c2 * c2) : 0.0;
    }
    float ids = useIds == 0 || abs(s.g.w) == abs(s0.g.w) ? 1.0 : 0.0;
    return normal * ids;
}

float geometricTerm(Surface s, Surface s0) {
    return geometricTerm(s, s0, 1.0);
}

// A fit's weight of data pixel s for centre s0: the geometric term times (1 - |n0|^8 (|n0| -
// |n|))^4 where the pixel's normal is the shorter. A pixel's normal is the mean of
// its samples': shorter than the centre's where fewer of them saw the centre's surface (a
// mirror's rim that reflects a wall beside what lies behind it), so it is data to the
// centre's plane only as far as it shares that surface.
float dataTerm(Surface s, Surface s0) {
    if (useNormals == 0) return geometricTerm(s, s0);
    float l0 = length(s0.g.xyz), l02 = l0 * l0, l04 = l02 * l02;
    return geometricTerm(s, s0, 1.0 - l04 * l04 * max(0.0, l0 - length(s.g.xyz)));
}

// A pixel's weight of a centre's fit in the gather: the data term, and a thousandth of the
// geometric term, so a pixel that no centre takes as data (a one-sample firefly whose other
// samples saw nothing) still takes the fits of the surface its normal points along.
float gatherTerm(Surface s, Surface s0) {
    if (useNormals == 0) return geometricTerm(s, s0);
    return dataTerm(s, s0) + PIVOT_GATHER_FALLBACK * geometricTerm(s, s0);
}

// Whether a pixel lies beside other ids: 0 when a 4-neighbour has other ids (the pixel may
// straddle an object or part boundary and mix both sides), else 1. The ratio stage keeps
// those that mix in a side far from their own (the boundary term w_b); the others are data
// but no centres of fits.
float boundaryTerm(int x, int y) {
    if (useIds == 0) return 1.0;
    int i = y * gw + x;
    if (x > 0 && idTerm(i - 1, i) == 0.0) return 0.0;
    if (x + 1 < gw && idTerm(i + 1, i) == 0.0) return 0.0;
    if (y > 0 && idTerm(i - gw, i) == 0.0) return 0.0;
    if (y + 1 < gh && idTerm(i + gw, i) == 0.0) return 0.0;
    return 1.0;
}
