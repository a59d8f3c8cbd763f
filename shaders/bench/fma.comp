#version 450
#extension GL_GOOGLE_include_directive : require

#include "bench/fma.h"

layout(local_size_x = BENCH_FMA_LOCAL_SIZE) in;
layout(std430, binding = BENCH_FMA_SRC) readonly buffer Src { vec4 src[]; };
layout(std430, binding = BENCH_FMA_DST) writeonly buffer Dst { vec4 dst[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    vec4 x[BENCH_FMA_CHAINS];
    for (int k = 0; k < BENCH_FMA_CHAINS; ++k) x[k] = src[i] + float(k);
    vec4 scale = vec4(push.scale), offset = vec4(push.offset);
    for (uint n = 0; n < push.iterations; ++n)
        for (int k = 0; k < BENCH_FMA_CHAINS; ++k) x[k] = fma(x[k], scale, offset);
    vec4 sum = x[0];
    for (int k = 1; k < BENCH_FMA_CHAINS; ++k) sum += x[k];
    dst[i] = sum;
}
