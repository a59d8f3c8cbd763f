// The geometric terms of the pivot filter (section 4.4), for kernels that declare the
// buffers `normals` (3 planes) and `ids` (2 planes: object, part), the specialization
// constants useNormals / useIds and the int `planeSize` (width x height).

// (n.n0)^4 when n.n0 > 1/2 for the unit normals at pixels i and i0, else 0; two zero
// normals (no surface) give 1, one gives 0.
float normalTerm(int i, int i0) {
    if (useNormals == 0) return 1.0;
    vec3 n = vec3(normals[i], normals[planeSize + i], normals[2 * planeSize + i]);
    vec3 n0 = vec3(normals[i0], normals[planeSize + i0], normals[2 * planeSize + i0]);
    float len = dot(n, n), len0 = dot(n0, n0);
    if (len == 0.0 && len0 == 0.0) return 1.0;
    if (len == 0.0 || len0 == 0.0) return 0.0;
    float d = dot(n, n0) / sqrt(len * len0);
    return d > 0.5 ? d * d * d * d : 0.0;
}

// 0 across object boundaries and between parts: the ids differ.
float idTerm(int i, int i0) {
    if (useIds == 0) return 1.0;
    return ids[i] == ids[i0] && ids[planeSize + i] == ids[planeSize + i0] ? 1.0 : 0.0;
}
