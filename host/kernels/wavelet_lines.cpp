#include "host/kernels/wavelet_lines.h"

#include "host/error.h"

#include <cstring>
#include <vector>

namespace mcd {

void CheckWaveletTemporary(const vk::ImageView &tmp, const vk::ImageView &src,
                           const vk::ImageView &dst, int width, const char *kernel) {
    if (tmp.buffer == src.buffer || tmp.buffer == dst.buffer)
        throw Error(std::string(kernel) + ": the temporary must be a buffer of its own");
    if (tmp.stride % 4 != 0 || tmp.plane % 4 != 0 || tmp.stride < (width + 3) / 4 * 4)
        throw Error(std::string(kernel) +
                    ": the temporary's rows must be padded to a multiple of 4 floats");
}

void RecordWaveletLinePass(vk::Context &context, vk::Recorder &recorder, const char *kernel,
                           const uint32_t *spirv, size_t spirvBytes, WaveletBasis basis,
                           int axis, int width, int height, int channels,
                           const vk::ImageView &src, const vk::ImageView &dst,
                           const std::string &label, std::initializer_list<float> extra,
                           std::initializer_list<const vk::Buffer *> reads,
                           std::initializer_list<std::pair<uint32_t, int32_t>> spec) {
    bool rows = axis == WAVELET_AXIS_ROWS;
    bool vec4 = rows && src.stride % 4 == 0 && src.plane % 4 == 0 && dst.stride % 4 == 0 &&
                dst.plane % 4 == 0;
    vk::KernelDesc desc{
        kernel,
        spirv,
        spirvBytes,
        uint32_t(WAVELET_LINES_BINDINGS + reads.size()),
        uint32_t(sizeof(shader::WaveletLinesPush) + extra.size() * sizeof(float)),
        {{WAVELET_SPEC_BASIS, int32_t(basis)},
         {WAVELET_SPEC_AXIS, axis},
         {WAVELET_SPEC_VEC4, vec4 ? 1 : 0}}};
    desc.specialization.insert(desc.specialization.end(), spec.begin(), spec.end());
    const vk::Kernel &k = context.GetKernel(desc);
    shader::WaveletLinesPush lines{width, height, src.stride, src.plane, dst.stride, dst.plane};
    std::vector<char> push(sizeof(lines) + extra.size() * sizeof(float));
    std::memcpy(push.data(), &lines, sizeof(lines));
    std::memcpy(push.data() + sizeof(lines), std::data(extra), extra.size() * sizeof(float));
    // Rows: one invocation per row, a segment of WAVELET_TILE positions per group along x;
    // columns the other way round.
    auto divUp = [](int a, int b) { return uint32_t((a + b - 1) / b); };
    uint32_t groupsX = rows ? divUp(width, WAVELET_TILE) : divUp(width, WAVELET_LOCAL_SIZE);
    uint32_t groupsY = rows ? divUp(height, WAVELET_LOCAL_SIZE) : divUp(height, WAVELET_TILE);
    std::vector<vk::Binding> bindings{{src.buffer, vk::Access::Read},
                                      {dst.buffer, vk::Access::Write}};
    for (const vk::Buffer *buffer : reads) bindings.push_back({buffer, vk::Access::Read});
    recorder.Dispatch(k, label + (rows ? ".rows" : ".columns"), bindings, push.data(), groupsX,
                      groupsY, uint32_t(channels));
}

}  // namespace mcd
