#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/distance.h"

// One invocation per (PIX consecutive centres of a row, offset): x across, strip row and
// offset from the grid. The lane's patches overlap, so each term row is fetched once for
// all of them (PIX + 2w texels, not PIX (2w + 1)) and summed per centre in the same order
// as one centre alone (the distances are the same bits). On lavapipe the texel fetches
// dominate: 8 centres per lane, 512x512: 330 -> 240 ms (4 and 16 per lane were slower).
layout(local_size_x = RHF_DISTANCE_LOCAL_SIZE) in;
layout(constant_id = RHF_DISTANCE_SPEC_SEARCH_HALF) const int B = 6;
layout(constant_id = RHF_DISTANCE_SPEC_PATCH_HALF) const int PW = 1;
const int SIDE = 2 * B + 1;
const int PIX = RHF_DISTANCE_PIXELS_PER_LANE;
const int COLS = PIX + 2 * PW;
layout(binding = RHF_DISTANCE_SUM) uniform samplerBuffer termSum;
layout(binding = RHF_DISTANCE_COUNT) uniform samplerBuffer termCount;
layout(std430, binding = RHF_DISTANCE_OUT) writeonly buffer Distance { float dist[]; };

// The distance of centre (x, y) to the patch at offset (ox, oy), k = ox + b, one centre
// alone; near the border the patch shrinks to w0.
float CentreDistance(int x, int y, int ox, int oy, int k) {
    int qx = x + ox, qy = y + oy;
    int w0 = min(min(PW, min(x, y)), min(push.width - 1 - x, push.height - 1 - y));
    if (qx < w0 || qx > push.width - 1 - w0 || qy < w0 || qy > push.height - 1 - w0)
        return -1.0;
    // Offsets with oy < 0: the terms of -o, stored at the candidate's pixels.
    bool mirrored = oy < 0;
    int plane = mirrored ? -oy * SIDE + 2 * B - k : oy * SIDE + k;
    int sx = x + (mirrored ? ox : 0), sy = y + (mirrored ? oy : 0) - push.termBase;
    int centre = (plane * push.termRows + sy) * push.width + sx;
    float sum = 0.0, count = 0.0;
    bool vetoed = false;  // a pixel pair marked by terms.comp (count -1)
    for (int ty = -w0; ty <= w0; ++ty)
        for (int tx = -w0; tx <= w0; ++tx) {
            float c = texelFetch(termCount, centre + ty * push.width + tx).r;
            sum += texelFetch(termSum, centre + ty * push.width + tx).r;
            count += c;
            vetoed = vetoed || c < 0.0;
        }
    return vetoed ? -1.0 : sum / (count + 1e-4);
}

void main() {
    int x0 = int(gl_GlobalInvocationID.x) * PIX, r = int(gl_WorkGroupID.y),
        o = int(gl_WorkGroupID.z);
    if (x0 >= push.width) return;
    int ox = o % SIDE - B, oy = o / SIDE - B, k = o % SIDE;
    int y = push.rowBase + r, qy = y + oy;
    int at = (o * push.rows + r) * push.width + x0;
    // Whole patches in the rows of the centres and of the candidates; the columns are
    // checked per centre below.
    bool inside = y >= PW && y <= push.height - 1 - PW && qy >= PW && qy <= push.height - 1 - PW;
    if (inside) {
        bool mirrored = oy < 0;
        int plane = mirrored ? -oy * SIDE + 2 * B - k : oy * SIDE + k;
        int sx0 = x0 + (mirrored ? ox : 0) - PW, sy = y + (mirrored ? oy : 0) - push.termBase;
        float sum[PIX], count[PIX], rowSum[COLS], rowCount[COLS];
        bool vetoed[PIX];
        [[unroll]] for (int j = 0; j < PIX; ++j) {
            sum[j] = 0.0;
            count[j] = 0.0;
            vetoed[j] = false;
        }
        [[unroll]] for (int ty = -PW; ty <= PW; ++ty) {
            int row = (plane * push.termRows + sy + ty) * push.width;
            // Columns off the image belong to centres whose candidate is outside (-1).
            [[unroll]] for (int c = 0; c < COLS; ++c) {
                int texel = row + clamp(sx0 + c, 0, push.width - 1);
                rowCount[c] = texelFetch(termCount, texel).r;
                rowSum[c] = texelFetch(termSum, texel).r;
            }
            [[unroll]] for (int j = 0; j < PIX; ++j)
                [[unroll]] for (int tx = 0; tx <= 2 * PW; ++tx) {
                    float c = rowCount[j + tx];
                    sum[j] += rowSum[j + tx];
                    count[j] += c;
                    vetoed[j] = vetoed[j] || c < 0.0;
                }
        }
        [[unroll]] for (int j = 0; j < PIX; ++j) {
            int x = x0 + j, qx = x + ox;
            bool fits = qx >= PW && qx <= push.width - 1 - PW;
            if (x >= PW && x <= push.width - 1 - PW)
                dist[at + j] = !fits || vetoed[j] ? -1.0 : sum[j] / (count[j] + 1e-4);
        }
        // Centres within w of the left or right edge (shrunk patches), one at a time: j in
        // [0, left) and [right, end). A loop, not a branch: on lavapipe a branch runs for the
        // whole vector of 8 lanes when one takes it (every centre of the first and last
        // vector of a row went this way before, a large share of the kernel's time).
        int left = clamp(PW - x0, 0, PIX), end = min(PIX, push.width - x0);
        int right = max(clamp(push.width - PW - x0, 0, PIX), left);
        int border = left + max(end - right, 0);
        for (int i = 0; i < border; ++i) {
            int j = i < left ? i : right + i - left;
            dist[at + j] = CentreDistance(x0 + j, y, ox, oy, k);
        }
    } else {
        // Near the border: one centre at a time, with its shrunk patch.
        for (int j = 0; j < PIX && x0 + j < push.width; ++j)
            dist[at + j] = CentreDistance(x0 + j, y, ox, oy, k);
    }
}
