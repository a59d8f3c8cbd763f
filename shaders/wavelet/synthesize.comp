#version 450
#extension GL_GOOGLE_include_directive : require

#include "wavelet/wavelet.h"
#include "wavelet/synthesize.h"

layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(std430, binding = WAVELET_SYNTHESIZE_LOW) readonly buffer Low { float low[]; };
layout(std430, binding = WAVELET_SYNTHESIZE_COEF) readonly buffer Coef { float coef[]; };
layout(std430, binding = WAVELET_SYNTHESIZE_DST) writeonly buffer Dst { float dst[]; };

#include "wavelet/lifting.glsl"

// Coefficient at (interleaved) position p of an axis of length n, folded like the
// forward transform's signal. Haar's phantom detail past an odd end is zero (-1 here).
int MirrorSynthesis(int p, int n) {
    if (WAVELET == MCD_WAVELET_HAAR && n > 1 && (p < 0 || p >= n)) return -1;
    return MirrorAnalysis(p, n);
}

void main() {
    int lid = int(gl_LocalInvocationIndex);
    int channel = int(gl_WorkGroupID.z);
    ivec2 block = ivec2(gl_WorkGroupID.xy) * WAVELET_TILE;
    ivec2 origin = block - WAVELET_HALO;
    bool liftX = push.width > 1, liftY = push.height > 1;

    // Gather the interleaved coefficients of the tile and undo the output scaling.
    for (int i = lid; i < kExt * kExt; i += kLocal) {
        int ty = i / kExt, tx = i - ty * kExt;
        int x = MirrorSynthesis(origin.x + tx, push.width);
        int y = MirrorSynthesis(origin.y + ty, push.height);
        float v = 0.0;
        if (x >= 0 && y >= 0) {
            bool lowX = !liftX || (x & 1) == 0, lowY = !liftY || (y & 1) == 0;
            int bx = BandIndex(x, push.width), by = BandIndex(y, push.height);
            if (lowX && lowY)
                v = low[channel * push.lowPlane + by * push.lowStride + bx];
            else
                v = coef[channel * push.coefPlane + by * push.coefStride + bx];
            if (liftX) v *= lowX ? 1.0 / LowScale() : 1.0 / HighScale();
            if (liftY) v *= lowY ? 1.0 / LowScale() : 1.0 / HighScale();
        }
        tile[i] = v;
    }
    barrier();

    // Columns over the whole tile (the row pass needs the apron columns), then rows.
    if (liftY) InverseY(0, kExt);
    if (liftX) InverseX(WAVELET_HALO, WAVELET_HALO + WAVELET_TILE);

    for (int i = lid; i < WAVELET_TILE * WAVELET_TILE; i += kLocal) {
        int ly = i / WAVELET_TILE, lx = i - ly * WAVELET_TILE;
        int px = block.x + lx, py = block.y + ly;
        if (px >= push.width || py >= push.height) continue;
        dst[channel * push.dstPlane + py * push.dstStride + px] =
            tile[(ly + WAVELET_HALO) * kExt + lx + WAVELET_HALO];
    }
}
