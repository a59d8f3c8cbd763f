#include "host/kernels/wavelet_lines.h"

#include "host/error.h"

#include <algorithm>
#include <vector>

namespace mcd {

void CheckWaveletTemporary(const vk::ImageView &tmp, const vk::ImageView &src,
                           const vk::ImageView &dst, int width, const char *kernel) {
    if (tmp.buffer == src.buffer || tmp.buffer == dst.buffer)
        throw Error(std::string(kernel) + ": the temporary must be a buffer of its own",
                    ErrorKind::Internal);
    if (tmp.stride % 4 != 0 || tmp.plane % 4 != 0 || tmp.stride < (width + 3) / 4 * 4)
        throw Error(std::string(kernel) +
                        ": the temporary's rows must be padded to a multiple of 4 floats",
                    ErrorKind::Internal);
}

int WaveletInteriorSegments(int n) {
    return std::max(n - WAVELET_TILE - WAVELET_HALO, 0) / WAVELET_TILE;
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
    pass.lines = {width, height, src.stride, src.plane, dst.stride, dst.plane};
    pass.bindings = {{WAVELET_LINES_SRC, src.buffer, vk::Access::Read},
                     {WAVELET_LINES_DST, dst.buffer, vk::Access::Write}};
    for (const vk::Binding &read : reads) {
        if (read.access != vk::Access::Read)
            throw Error(
                std::string(kernel) + ": the extra bindings of a line pass are read only",
                ErrorKind::Internal);
        pass.bindings.push_back(read);
    }
    // Rows: one invocation per row, a segment of WAVELET_TILE positions per group along x;
    // columns the other way round. The rows pass's interior segments move vec4s, so they
    // run apart only with vec4 access.
    int length = rows ? width : height, lines = rows ? height : width;
    int segments = (length + WAVELET_TILE - 1) / WAVELET_TILE;
    int interior =
        (rows && !vec4) || length < WAVELET_SPLIT_LENGTH ? 0 : WaveletInteriorSegments(length);
    auto variant = [&](int part) {
        vk::KernelDesc d = desc;
        d.specialization.push_back({WAVELET_SPEC_PART, part});
        return &context.GetKernel(d);
    };
    auto add = [&](int part, const char *suffix, int count) {
        uint32_t across = uint32_t((lines + WAVELET_LOCAL_SIZE - 1) / WAVELET_LOCAL_SIZE);
        WaveletLineDispatch d{variant(part), suffix, 0, 0, uint32_t(channels)};
        (rows ? d.groupsX : d.groupsY) = uint32_t(count);
        (rows ? d.groupsY : d.groupsX) = across;
        pass.dispatches.push_back(d);
    };
    if (interior == 0) {
        add(WAVELET_PART_ALL, rows ? ".rows" : ".columns", segments);
    } else {
        add(WAVELET_PART_INTERIOR, rows ? ".rows" : ".columns", interior);
        add(WAVELET_PART_EDGES, rows ? ".rows.edges" : ".columns.edges", segments - interior);
    }
    return pass;
}

}  // namespace mcd
