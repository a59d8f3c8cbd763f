#include "host/kernels/rhf_downsample.h"

#include <fmt/format.h>

#include <cmath>

#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "rhf/downsample.h"
#include "rhf/downsample_spv.h"

namespace mcd {

std::vector<float> RhfGaussianTaps(double sigma, int step) {
    int radius = int(std::ceil(sigma * std::sqrt(4 * std::log(10.0))));
    // Tap i sits at floor((x + 0.5) step) - radius + i, the sample point at
    // (x + 0.5) step - 0.5: half a pixel before the middle tap when step is even.
    double centre = radius - (step % 2 == 0 ? 0.5 : 0.0);
    std::vector<double> taps(2 * radius + 1);
    double total = 0;
    for (int i = 0; i <= 2 * radius; ++i) {
        double t = (i - centre) / sigma;
        total += taps[i] = std::exp(-0.5 * t * t);
    }
    std::vector<float> out;
    for (double t : taps) out.push_back(float(t / total));
    return out;
}

vk::KernelDesc RhfDownsampleKernel() {
    return {"rhf_downsample",
            k_rhf_downsample_spv,
            sizeof(k_rhf_downsample_spv),
            RHF_DOWNSAMPLE_BINDINGS,
            sizeof(shader::RhfDownsamplePush),
            {},
            1u << RHF_DOWNSAMPLE_SRC};
}

void RecordRhfDownsample(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &src,
                         int srcWidth, int srcHeight, int planes, int step,
                         const vk::Buffer &weights, int radius, vk::Buffer &scratch,
                         vk::Buffer &dst) {
    int dstWidth = (srcWidth + step - 1) / step, dstHeight = (srcHeight + step - 1) / step;
    if (planes <= 0 || step <= 0 || radius < 0 ||
        src.Bytes() < size_t(planes) * srcWidth * srcHeight * sizeof(float) ||
        scratch.Bytes() < size_t(planes) * dstWidth * srcHeight * sizeof(float) ||
        dst.Bytes() < size_t(planes) * dstWidth * dstHeight * sizeof(float) ||
        weights.Bytes() < size_t(2 * radius + 1) * sizeof(float))
        throw Error(fmt::format("rhf downsample: {} planes of {}x{} by {} do not fit the "
                                "buffers",
                                planes, srcWidth, srcHeight, step),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel(RhfDownsampleKernel());
    auto groups = [](int n) {
        return uint32_t((n + RHF_DOWNSAMPLE_LOCAL_SIZE - 1) / RHF_DOWNSAMPLE_LOCAL_SIZE);
    };
    shader::RhfDownsamplePush alongX{srcWidth, srcHeight, dstWidth, srcHeight, step, radius, 0};
    recorder.Dispatch(kernel, "rhf.downsample",
                      {{RHF_DOWNSAMPLE_SRC, &src, vk::Access::Read},
                       {RHF_DOWNSAMPLE_DST, &scratch, vk::Access::Write},
                       {RHF_DOWNSAMPLE_WEIGHTS, &weights, vk::Access::Read}},
                      alongX, groups(dstWidth), uint32_t(srcHeight), uint32_t(planes));
    shader::RhfDownsamplePush alongY{dstWidth, srcHeight, dstWidth, dstHeight, step, radius, 1};
    recorder.Dispatch(kernel, "rhf.downsample",
                      {{RHF_DOWNSAMPLE_SRC, &scratch, vk::Access::Read},
                       {RHF_DOWNSAMPLE_DST, &dst, vk::Access::Write},
                       {RHF_DOWNSAMPLE_WEIGHTS, &weights, vk::Access::Read}},
                      alongY, groups(dstWidth), uint32_t(dstHeight), uint32_t(planes));
}

}  // namespace mcd
