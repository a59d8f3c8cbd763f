// Record the calibration kernels of `bench kernels` (shaders/bench/): a streaming copy
// for the device's bandwidth and an FMA loop for its arithmetic rate.
#pragma once

#include <cstdint>

#include "host/vk/buffer.h"
#include "host/vk/recorder.h"

namespace mcd {

// dst[i] = src[i] for `count` vec4s (both buffers hold at least 16 * count bytes).
void RecordBenchStream(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                       const vk::Buffer &dst, uint32_t count);

// shaders/bench/fma.h's chains over `count` vec4s of `src` into `dst`.
void RecordBenchFma(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                    const vk::Buffer &dst, uint32_t count, uint32_t iterations, float scale,
                    float offset);

// Floating-point operations of one RecordBenchFma dispatch (shaders/bench/fma.h).
double BenchFmaFlops(uint32_t count, uint32_t iterations);

}  // namespace mcd
