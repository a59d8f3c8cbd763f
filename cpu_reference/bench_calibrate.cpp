#include "cpu_reference/bench_calibrate.h"

#include <cstddef>

namespace mcd::ref {

std::vector<double> BenchFma(const std::vector<float> &src, uint32_t iterations, float scale,
                             float offset, uint64_t *flops) {
    constexpr int kChains = 4, kLanes = 4;
    std::vector<double> out(src.size());
    for (std::size_t v = 0; v + kLanes <= src.size(); v += kLanes) {
        for (int lane = 0; lane < kLanes; ++lane) {
            double sum = 0;
            for (int k = 0; k < kChains; ++k) {
                double x = double(src[v + lane]) + k;
                ++*flops;
                for (uint32_t n = 0; n < iterations; ++n) {
                    x = x * scale + offset;
                    *flops += 2;
                }
                if (k == 0) {
                    sum = x;
                } else {
                    sum += x;
                    ++*flops;
                }
            }
            out[v + lane] = sum;
        }
    }
    return out;
}

}  // namespace mcd::ref
