#include "host/kernels/bench_calibrate.h"

#include <fmt/format.h>

#include "bench/fma.h"
#include "bench/fma_spv.h"
#include "bench/stream.h"
#include "bench/stream_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {
namespace {

// Both kernels read and write `count` vec4s.
void CheckVec4Buffers(const char *what, const vk::Buffer &src, const vk::Buffer &dst,
                      uint32_t count) {
    uint64_t bytes = uint64_t(count) * 16;
    if (src.Bytes() < bytes || dst.Bytes() < bytes)
        throw Error(fmt::format("{}: {} vec4s need {} bytes; '{}' has {}, '{}' {}", what, count,
                                bytes, src.Name(), src.Bytes(), dst.Name(), dst.Bytes()),
                    ErrorKind::Internal);
}

uint32_t Groups(uint32_t count, uint32_t localSize) {
    return (count + localSize - 1) / localSize;
}

}  // namespace

void RecordBenchStream(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                       const vk::Buffer &dst, uint32_t count) {
    CheckVec4Buffers("bench stream", src, dst, count);
    const vk::Kernel &kernel = context.GetKernel({"bench_stream",
                                                  k_bench_stream_spv,
                                                  sizeof(k_bench_stream_spv),
                                                  BENCH_STREAM_BINDINGS,
                                                  sizeof(shader::BenchStreamPush),
                                                  {}});
    shader::BenchStreamPush push{count};
    recorder.Dispatch(kernel, "bench.stream",
                      {{BENCH_STREAM_SRC, &src, vk::Access::Read},
                       {BENCH_STREAM_DST, &dst, vk::Access::Write}},
                      push, Groups(count, BENCH_STREAM_LOCAL_SIZE));
}

void RecordBenchFma(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                    const vk::Buffer &dst, uint32_t count, uint32_t iterations, float scale,
                    float offset) {
    CheckVec4Buffers("bench fma", src, dst, count);
    const vk::Kernel &kernel = context.GetKernel({"bench_fma",
                                                  k_bench_fma_spv,
                                                  sizeof(k_bench_fma_spv),
                                                  BENCH_FMA_BINDINGS,
                                                  sizeof(shader::BenchFmaPush),
                                                  {}});
    shader::BenchFmaPush push{count, iterations, scale, offset};
    recorder.Dispatch(
        kernel, "bench.fma",
        {{BENCH_FMA_SRC, &src, vk::Access::Read}, {BENCH_FMA_DST, &dst, vk::Access::Write}},
        push, Groups(count, BENCH_FMA_LOCAL_SIZE));
}

double BenchFmaFlops(uint32_t count, uint32_t iterations) {
    const double chains = BENCH_FMA_CHAINS, lanes = 4;
    double perInvocation =
        double(iterations) * chains * lanes * 2 + lanes * chains + lanes * (chains - 1);
    return perInvocation * count;
}

}  // namespace mcd
