// The geometric terms of the pivot filter (section 4.4), for kernels that declare the
// vec4 texel buffer `guides` (per pixel two texels, PIVOT_GUIDE_STRIDE floats: normal x, y,
// z, 0, then object id, part id, 0, 0), the specialization constants useNormals / useIds
// and the ints `planeSize` (width x height) and `gw`, `gh` (width, height).

// Pixel i's normal and its object and part ids: one fetch each.
vec3 NormalAt(int i) {
    return texelFetch(guides, 2 * i).xyz;
}

vec2 IdsAt(int i) {
    return texelFetch(guides, 2 * i + 1).xy;
}

// (n.n0)^4 when n.n0 > 1/2 for the unit normals at pixels i and i0, else 0; two zero
// normals (no surface) give 1, one gives 0.
float normalTerm(int i, int i0) {
    if (useNormals == 0) return 1.0;
    vec3 n = NormalAt(i);
    vec3 n0 = NormalAt(i0);
    float len = dot(n, n), len0 = dot(n0, n0);
    if (len == 0.0 && len0 == 0.0) return 1.0;
    if (len == 0.0 || len0 == 0.0) return 0.0;
    float d = dot(n, n0) / sqrt(len * len0);
    return d > 0.5 ? d * d * d * d : 0.0;
}

// 0 across object boundaries and between parts: the ids differ.
float idTerm(int i, int i0) {
    if (useIds == 0) return 1.0;
    vec2 ids = IdsAt(i), ids0 = IdsAt(i0);
    return ids.x == ids0.x && ids.y == ids0.y ? 1.0 : 0.0;
}

// A pixel's guides, read once where one side of many comparisons stays the same.
struct Surface {
    vec3 n;
    float len;  // dot(n, n)
    float object, part;
};

Surface surfaceAt(int i) {
    Surface s = Surface(vec3(0.0), 0.0, 0.0, 0.0);
    if (useNormals != 0) {
        s.n = NormalAt(i);
        s.len = dot(s.n, s.n);
    }
    if (useIds != 0) {
        vec2 ids = IdsAt(i);
        s.object = ids.x;
        s.part = ids.y;
    }
    return s;
}

// normalTerm(i, i0) * idTerm(i, i0) from the two pixels' surfaces, bit for bit.
float geometricTerm(Surface s, Surface s0) {
    float normal = 1.0;
    if (useNormals != 0) {
        if (s.len == 0.0 && s0.len == 0.0)
            normal = 1.0;
        else if (s.len == 0.0 || s0.len == 0.0)
            normal = 0.0;
        else {
            float d = dot(s.n, s0.n) / sqrt(s.len * s0.len);
            normal = d > 0.5 ? d * d * d * d : 0.0;
        }
    }
    float ids = useIds == 0 || (s.object == s0.object && s.part == s0.part) ? 1.0 : 0.0;
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
