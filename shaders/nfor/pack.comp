#version 450
#extension GL_GOOGLE_include_directive : require

#include "nfor/fit.h"

layout(local_size_x = NFOR_LOCAL_SIZE) in;
layout(constant_id = NFOR_SPEC_CHANNELS) const int channels = 3;
layout(constant_id = NFOR_SPEC_FEATURES) const int featureCount = 7;
const int featureVec4s = NFOR_FEATURE_VEC4S(featureCount);
const int packedFloats = 4 * NFOR_PACKED_VEC4S(featureCount);
layout(std430, binding = NFOR_PACK_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = NFOR_PACK_FEATURES) readonly buffer Features { float features[]; };
layout(std430, binding = NFOR_PACK_MASK) readonly buffer Mask { float mask[]; };
layout(std430, binding = NFOR_PACK_OUT) writeonly buffer Out { float packed[]; };

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    int w = push.width, h = push.height;
    if (x >= w) return;
    int pixel = y * w + x, base = pixel * packedFloats, n = w * h;
    packed[base] = mask[pixel];
    for (int j = 0; j < 4 * featureVec4s - 1; ++j)
        packed[base + 1 + j] = j < featureCount ? features[j * n + pixel] : 0.0;
    for (int c = 0; c < 4; ++c)
        packed[base + 4 * featureVec4s + c] = c < channels ? color[c * n + pixel] : 0.0;
}
