#version 450
#extension GL_GOOGLE_include_directive : require

#include "bench/stream.h"

layout(local_size_x = BENCH_STREAM_LOCAL_SIZE) in;
layout(std430, binding = BENCH_STREAM_SRC) readonly buffer Src { vec4 src[]; };
layout(std430, binding = BENCH_STREAM_DST) writeonly buffer Dst { vec4 dst[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < push.count) dst[i] = src[i];
}
