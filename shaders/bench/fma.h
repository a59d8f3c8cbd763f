// The arithmetic calibration of `bench kernels`: per invocation i, BENCH_FMA_CHAINS
// independent vec4 chains start at src[i] + k (chain k) and take `iterations` steps
// x = fma(x, scale, offset); dst[i] is the chains' sum. Independent chains keep the FMA
// units busy despite each step's latency. Floating-point operations per invocation:
// iterations * BENCH_FMA_CHAINS * 4 lanes * 2 (an FMA counts as a multiply and an add),
// plus 4 * BENCH_FMA_CHAINS adds for the chains' start and 4 * (BENCH_FMA_CHAINS - 1) for
// the sum.
#ifndef MCD_SHADERS_BENCH_FMA_H
#define MCD_SHADERS_BENCH_FMA_H

#define BENCH_FMA_SRC 0
#define BENCH_FMA_DST 1
#define BENCH_FMA_BINDINGS 2
#define BENCH_FMA_LOCAL_SIZE 256
#define BENCH_FMA_CHAINS 4

#ifdef __cplusplus
namespace mcd::shader {
struct BenchFmaPush {
#else
layout(push_constant) uniform BenchFmaPush {
#endif
    uint count;       // invocations (vec4s in and out)
    uint iterations;  // FMA steps per chain
    float scale;      // below 1 in magnitude, so the chains stay bounded
    float offset;
#ifdef __cplusplus
};
static_assert(sizeof(BenchFmaPush) == 16);
}  // namespace mcd::shader
#else
} push;
#endif

#endif
