#version 450
#extension GL_GOOGLE_include_directive : require

#include "wavelet/wavelet.h"
#include "wavelet/analyze.h"

layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(std430, binding = WAVELET_ANALYZE_SRC) readonly buffer Src { float src[]; };
layout(std430, binding = WAVELET_ANALYZE_COEF) writeonly buffer Coef { float coef[]; };
layout(std430, binding = WAVELET_ANALYZE_LOW) writeonly buffer Low { float low[]; };

#include "wavelet/lifting.glsl"

void main() {
    int lid = int(gl_LocalInvocationIndex);
    int channel = int(gl_WorkGroupID.z);
    ivec2 block = ivec2(gl_WorkGroupID.xy) * WAVELET_TILE;
    ivec2 origin = block - WAVELET_HALO;
    bool liftX = push.width > 1, liftY = push.height > 1;

    // Load the tile with its apron, folding positions outside the region back in.
    int srcBase = channel * push.srcPlane;
    for (int i = lid; i < kExt * kExt; i += kLocal) {
        int ty = i / kExt, tx = i - ty * kExt;
        int x = MirrorAnalysis(origin.x + tx, push.width);
        int y = MirrorAnalysis(origin.y + ty, push.height);
        tile[i] = src[srcBase + y * push.srcStride + x];
    }
    barrier();

    // Rows over the whole tile (the column pass needs the apron rows), then the columns
    // of the block. Scaling is applied at the write: it commutes with the other axis.
    if (liftX) ForwardX(0, kExt);
    if (liftY) ForwardY(WAVELET_HALO, WAVELET_HALO + WAVELET_TILE);

    for (int i = lid; i < WAVELET_TILE * WAVELET_TILE; i += kLocal) {
        int ly = i / WAVELET_TILE, lx = i - ly * WAVELET_TILE;
        int px = block.x + lx, py = block.y + ly;
        if (px >= push.width || py >= push.height) continue;
        float v = tile[(ly + WAVELET_HALO) * kExt + lx + WAVELET_HALO];
        bool lowX = !liftX || (px & 1) == 0, lowY = !liftY || (py & 1) == 0;
        if (liftX) v *= lowX ? LowScale() : HighScale();
        if (liftY) v *= lowY ? LowScale() : HighScale();
        int bx = BandIndex(px, push.width), by = BandIndex(py, push.height);
        if (lowX && lowY)
            low[channel * push.lowPlane + by * push.lowStride + bx] = v;
        else
            coef[channel * push.coefPlane + by * push.coefStride + bx] = v;
    }
}
