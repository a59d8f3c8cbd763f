// The streaming calibration of `bench kernels`: dst[i] = src[i] for `count` vec4s, one
// invocation each, so the dispatch moves 32 bytes per invocation and computes nothing: its
// rate is the device's streaming bandwidth (the roofline's memory bound).
#ifndef MCD_SHADERS_BENCH_STREAM_H
#define MCD_SHADERS_BENCH_STREAM_H

#define BENCH_STREAM_SRC 0
#define BENCH_STREAM_DST 1
#define BENCH_STREAM_BINDINGS 2
#define BENCH_STREAM_LOCAL_SIZE 256

#ifdef __cplusplus
namespace mcd::shader {
struct BenchStreamPush {
#else
layout(push_constant) uniform BenchStreamPush {
#endif
    uint count;  // vec4s to copy
#ifdef __cplusplus
};
static_assert(sizeof(BenchStreamPush) == 4);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
