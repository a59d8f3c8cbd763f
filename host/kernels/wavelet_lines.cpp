#include "host/kernels/wavelet_lines.h"

#include "host/error.h"

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

WaveletLinePass MakeWaveletLinePass(vk::Context &context, const char *kernel,
                                    const uint32_t *spirv, size_t spirvBytes,
                                    uint32_t pushBytes, WaveletBasis basis, int axis, int width,
                                    int height, int channels, const vk::ImageView &src,
                                    const vk::MutableImageView &dst,
                                    std::initializer_list<vk::Binding> reads,
                                    std::initializer_list<std::pair<uint32_t, int32_t>> spec) {
    bool rows = axis == WAVELET_AXIS_ROWS;
    bool vec4 = rows && src.stride % 4 == 0 && src.plane % 4 == 0 && dst.stride % 4 == 0 &&
                dst.plane % 4 == 0;
    vk::KernelDesc desc{kernel,
                        spirv,
                        spirvBytes,
                        uint32_t(WAVELET_LINES_BINDINGS + reads.size()),
                        pushBytes,
                        {{WAVELET_SPEC_BASIS, int32_t(basis)},
                         {WAVELET_SPEC_AXIS, axis},
                         {WAVELET_SPEC_VEC4, vec4 ? 1 : 0}}};
    desc.specialization.insert(desc.specialization.end(), spec.begin(), spec.end());
    WaveletLinePass pass;
    pass.kernel = &context.GetKernel(desc);
    pass.lines = {width, height, src.stride, src.plane, dst.stride, dst.plane};
    pass.bindings = {{WAVELET_LINES_SRC, src.buffer, vk::Access::Read},
                     {WAVELET_LINES_DST, dst.buffer, vk::Access::Write}};
    for (const vk::Binding &read : reads) {
        if (read.access != vk::Access::Read)
            throw Error(std::string(kernel) +
                        ": the extra bindings of a line pass are read only");
        pass.bindings.push_back(read);
    }
    pass.suffix = rows ? ".rows" : ".columns";
    // Rows: one invocation per row, a segment of WAVELET_TILE positions per group along x;
    // columns the other way round.
    auto divUp = [](int a, int b) { return uint32_t((a + b - 1) / b); };
    pass.groupsX = rows ? divUp(width, WAVELET_TILE) : divUp(width, WAVELET_LOCAL_SIZE);
    pass.groupsY = rows ? divUp(height, WAVELET_LOCAL_SIZE) : divUp(height, WAVELET_TILE);
    pass.groupsZ = uint32_t(channels);
    return pass;
}

}  // namespace mcd
