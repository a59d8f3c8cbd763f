// The calibration kernels of `bench kernels` (shaders/bench/fma.h), the CPU reference:
// the same chains in double, counting each floating-point operation as it is done.
#pragma once

#include <cstdint>
#include <vector>

namespace mcd::ref {

// `src` holds 4 * count floats (count vec4s); returns 4 * count sums of the chains. Adds
// the operations done to *flops (an FMA counts as two).
std::vector<double> BenchFma(const std::vector<float> &src, uint32_t iterations, float scale,
                             float offset, uint64_t *flops);

}  // namespace mcd::ref
