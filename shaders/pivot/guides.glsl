// The geometric terms of the pivot filter (section 4.4), for kernels that declare the
// vec4 texel buffer `guides` (per pixel two texels, PIVOT_GUIDE_STRIDE floats: the normal as
// a 4-vector, then object id, part id, 0, 0; PivotGuideBuffer), the specialization
// constants useNormals / useIds and the ints `planeSize` (width x height) and `gw`, `gh`
// (width, height).

// Pixel i's normal as a 4-vector, (unit normal, 0), or (0, 0, 0, 1) where the normal is
// zero (no surface): the dot product of two is n.n0 for unit normals, 1 for two zero
// normals and 0 for one, which is what the normal term needs (no sqrt, no division, no
// branch). One fetch.
vec4 NormalAt(int i) {
    return texelFetch(guides, 2 * i);
}

// Pixel i's object and part ids: one fetch.
vec2 IdsAt(int i) {
    return texelFetch(guides, 2 * i + 1).xy;
}

// 0 across object boundaries and between parts: the ids differ.
float idTerm(int i, int i0) {
    if (useIds == 0) return 1.0;
    vec2 ids = IdsAt(i), ids0 = IdsAt(i0);
    return ids.x == ids0.x && ids.y == ids0.y ? 1.0 : 0.0;
}

// A pixel's guides, read once where one side of many comparisons stays the same.
struct Surface {
    vec4 n;  // NormalAt
    vec2 ids;
};

Surface surfaceAt(int i) {
    Surface s = Surface(vec4(0.0), vec2(0.0));
    if (useNormals != 0) s.n = NormalAt(i);
    if (useIds != 0) s.ids = IdsAt(i);
    return s;
}

// The normal term (n.n0)^4 for n.n0 > 1/2 of unit normals, else 0; two zero normals give
// 1, one gives 0 (NormalAt); times the id terms.
float geometricTerm(Surface s, Surface s0) {
    float normal = 1.0;
    if (useNormals != 0) {
        float d = dot(s.n, s0.n);
        normal = d > 0.5 ? d * d * d * d : 0.0;
    }
    float ids = useIds == 0 || (s.ids.x == s0.ids.x && s.ids.y == s0.ids.y) ? 1.0 : 0.0;
    return normal * ids;
}

// The boundary term w_b as a property of a pixel: 0 when a 4-neighbour has other ids (the
// pixel may straddle an object or part boundary and mix both sides), else 1. The ratio
// stage marks such pixels as having no z: they give no data and keep their input.
float boundaryTerm(int x, int y) {
    if (useIds == 0) return 1.0;
    int i = y * gw + x;
    if (x > 0 && idTerm(i - 1, i) == 0.0) return 0.0;
    if (x + 1 < gw && idTerm(i + 1, i) == 0.0) return 0.0;
    if (y > 0 && idTerm(i - gw, i) == 0.0) return 0.0;
    if (y + 1 < gh && idTerm(i + gw, i) == 0.0) return 0.0;
    return 1.0;
}
