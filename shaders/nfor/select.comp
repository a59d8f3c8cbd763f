#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/select.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(std430, binding = NFOR_SELECT_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_SELECT_VARIANCE) readonly buffer Variance { float variance[]; };
layout(std430, binding = NFOR_SELECT_CANDIDATES) readonly buffer Candidates { float candidates[]; };
layout(std430, binding = NFOR_SELECT_HAT) readonly buffer Hat { float hat[]; };
layout(std430, binding = NFOR_SELECT_OUT) writeonly buffer Out { float outputs[]; };
layout(std430, binding = NFOR_SELECT_CHOICE) writeonly buffer Choice { float choice[]; };

int w, h;

// A candidate's SURE of each pixel its workgroup's windows read, made once (about 5 KiB at
// the largest radius, within the 16 KiB of shared memory Vulkan guarantees): the window sums
// below read them in the order they would sum sureAt, so the averages are the same floats.
#define NFOR_SELECT_TILE_WIDTH (NFOR_LOCAL_SIZE + 2 * NFOR_SURE_MAX_RADIUS)
#define NFOR_SELECT_TILE_ROWS (2 * NFOR_SURE_MAX_RADIUS + 1)
shared float sureTile[NFOR_SELECT_TILE_WIDTH * NFOR_SELECT_TILE_ROWS];

float sureAt(int k, int x, int y) {
    float e = 0.0;
    float influence = hat[(k * h + y) * w + x];
    for (int c = 0; c < channels; ++c) {
        int at = (c * h + y) * w + x;
        float d = candidates[((k * channels + c) * h + y) * w + x] - color[at];
        float v = variance[at];
        e += d * d - v + 2.0 * v * influence;
    }
    return e;
}

// Candidate k's squared difference from candidate 0 relative to candidate 0's magnitude.
float disagreementAt(int k, int x, int y) {
    float d = 0.0, mean = 0.0;
    for (int c = 0; c < channels; ++c) {
        float y0 = candidates[(c * h + y) * w + x];
        float e = candidates[((k * channels + c) * h + y) * w + x] - y0;
        d += e * e;
        mean += y0;
    }
    mean /= float(channels);
    return d / float(channels) / (mean * mean + float(NFOR_AGREEMENT_FLOOR));
}

// The last candidate k > 0 whose window mean disagreement is below push.agreement, else 0.
int agreeing(int x, int y) {
    int r = push.radius, best = 0;
    for (int k = 1; k < push.candidates; ++k) {
        float sum = 0.0;
        int count = 0;
        for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
            for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
                sum += disagreementAt(k, u, v);
                ++count;
            }
        if (sum / float(count) < push.agreement) best = k;
    }
    return best;
}

// Candidate k's SURE of the pixels the workgroup's windows read into sureTile (the tile's
// columns from x0, tileW of them, its rows from y - r). Every invocation takes part.
void fillSureTile(int k, int x0, int tileW, int y, int r) {
    int count = tileW * (2 * r + 1);
    for (int j = int(gl_LocalInvocationID.x); j < count; j += NFOR_LOCAL_SIZE) {
        int u = x0 + j % tileW, v = y - r + j / tileW;
        if (u >= 0 && u < w && v >= 0 && v < h) sureTile[j] = sureAt(k, u, v);
    }
    barrier();
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    int r = push.radius, best = 0;
    int x0 = int(gl_WorkGroupID.x) * NFOR_LOCAL_SIZE - r, tileW = NFOR_LOCAL_SIZE + 2 * r;
    float bestSure = 0.0;
    // The candidates in turn through one tile: the loop is the workgroup's, not the pixel's.
    for (int k = 0; k < (push.agreement > 0.0 ? 0 : push.candidates); ++k) {
        fillSureTile(k, x0, tileW, y, r);
        if (x < w) {
            float sum = 0.0;
            int count = 0;
            for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
                for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
                    sum += sureTile[(v - (y - r)) * tileW + u - x0];
                    ++count;
                }
            float mean = sum / float(count);
            if (k == 0 || mean < bestSure) {
                best = k;
                bestSure = mean;
            }
        }
        barrier();  // the next candidate's fill overwrites the tile
    }
    if (x >= w) return;
    if (push.agreement > 0.0) best = agreeing(x, y);
    for (int c = 0; c < channels; ++c)
        outputs[(c * h + y) * w + x] = candidates[((best * channels + c) * h + y) * w + x];
    choice[y * w + x] = float(best);
}
