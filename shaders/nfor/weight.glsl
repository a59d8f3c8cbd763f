// The weight of q in p's window and the regression's columns of q there, shared by regress
// and gather. Needs w, h, the packed and distance buffers, `featureCount` and
// `candidateCount`.
// Arrays are indexed by constants only (the loops are unrolled by the preprocessor to the
// largest counts, the spec constants fold the unused steps away), which keeps them in
// registers.

#define SEQ10(F, o) F(o + 0) F(o + 1) F(o + 2) F(o + 3) F(o + 4) F(o + 5) F(o + 6) F(o + 7) F(o + 8) F(o + 9)
#define SEQ13(F) SEQ10(F, 0) F(10) F(11) F(12)

float distanceOf(int px, int py, int qx, int qy) {
    int r = push.radius, ox = qx - px, oy = qy - py;
    int side = 2 * r + 1, centre = (side * side - 1) / 2;
    int index = (oy + r) * side + ox + r;
    // Offsets after the centre are stored at p, the others mirrored at q: one fetch either
    // way, its address selected (lavapipe runs both sides of a branch).
    bool stored = index > centre;
    int plane = stored ? index - centre - 1 : centre - 1 - index;
    int ax = stored ? px : qx, ay = stored ? py : qy;
    return texelFetch(distance, (plane * h + ay) * w + ax).x;
}

// A pixel's packed inputs (nfor/fit.h): the mask and features in slots[0..featureVec4s).
const int featureVec4s = NFOR_FEATURE_VEC4S(featureCount);
const int packedVec4s = NFOR_PACKED_VEC4S(featureCount);
#define FEATURE(slots, j) slots[((j) + 1) / 4][((j) + 1) % 4]
#define LOAD_SLOT(k) \
    if ((k) < featureVec4s) slots[k] = texelFetch(packed, base + (k));
#define LOAD_SLOTS(pixel)                  \
    {                                      \
        int base = (pixel) * packedVec4s;  \
        LOAD_SLOT(0) LOAD_SLOT(1) LOAD_SLOT(2) \
    }

// The mask and features of the pixel fixed over the loop (p in regress, q in gather).
vec4 fixedSlots[3];
void loadFixed(int fx, int fy) {
    vec4 slots[3];
    LOAD_SLOTS(fy * w + fx)
    fixedSlots = slots;
}

// The columns (1, dx / R, dy / R, F_q - F_p) into col, and q's weight in p's window: 0 for
// an emitter at `moving` (the pixel not fixed; the fixed one's mask is the caller's), 1 at
// q = p, else exp(-max(0, D) / k^2 - sum_j (s_j (F_q,j - F_p,j))^2), 0 beyond the cut.
// sign: 1 when q moves, -1 when p does. With candidateCount 2, secondWeight is the same
// weight at the second bandwidth.
float col[NFOR_MAX_FEATURES + 3];
float secondWeight;
#define COLUMN(j)                                                         \
    if ((j) < featureCount) {                                             \
        float d = sign * (FEATURE(slots, j) - FEATURE(fixedSlots, j));    \
        col[3 + (j)] = d;                                                 \
        float s = push.featureWeight[j] * d;                              \
        e += s * s;                                                       \
    }
float weightOf(int px, int py, int qx, int qy, int mx, int my, float sign) {
    vec4 slots[3];
    LOAD_SLOTS(my * w + mx)
    secondWeight = 0.0;
    if (slots[0].x == 0.0) return 0.0;
    col[0] = 1.0;
    col[1] = float(qx - px) / float(push.radius);
    col[2] = float(qy - py) / float(push.radius);
    float e = 0.0;
    SEQ10(COLUMN, 0)
    if (qx == px && qy == py) {
        secondWeight = 1.0;
        return 1.0;
    }
    float d = max(0.0, distanceOf(px, py, qx, qy));
    if (candidateCount > 1) {
        float e2 = e + d * push.secondInvBandwidth2;
        secondWeight = e2 > NFOR_EXP_CUT ? 0.0 : exp(-e2);
    }
    e += d * push.invBandwidth2;
    return e > NFOR_EXP_CUT ? 0.0 : exp(-e);
}
