// What the two line-lifting wavelet kernels share on the host: the grid of each pass and
// the check for the vec4 path. Layout only; the kernels' arithmetic lives in their GLSL.
#pragma once

#include <cstdint>

#include "host/error.h"
#include "host/vk/gpu_image.h"
#include "wavelet/tile.h"

namespace mcd {

struct WaveletGrid {
    uint32_t x, y, z;
};

inline WaveletGrid WaveletPassGrid(int axis, int width, int height, int channels) {
    auto divUp = [](int a, int b) { return uint32_t((a + b - 1) / b); };
    if (axis == WAVELET_AXIS_ROWS)
        return {divUp(width, WAVELET_TILE), divUp(height, WAVELET_LOCAL_SIZE),
                uint32_t(channels)};
    return {divUp(width, WAVELET_LOCAL_SIZE), divUp(height, WAVELET_TILE), uint32_t(channels)};
}

// The rows pass may move vec4s when both of its views keep rows and planes 16-byte aligned.
inline bool WaveletVec4Rows(const vk::ImageView &a, const vk::ImageView &b) {
    return a.stride % 4 == 0 && a.plane % 4 == 0 && b.stride % 4 == 0 && b.plane % 4 == 0;
}

// The temporary must not alias the source or destination, and its rows are padded to
// whole vec4s so the rows passes can always move vec4s through it.
inline void CheckWaveletTemporary(const vk::ImageView &tmp, const vk::ImageView &src,
                                  const vk::ImageView &dst, int width, const char *kernel) {
    if (tmp.buffer == src.buffer || tmp.buffer == dst.buffer)
        throw Error(std::string(kernel) + ": the temporary must be a buffer of its own");
    if (tmp.stride % 4 != 0 || tmp.plane % 4 != 0 || tmp.stride < (width + 3) / 4 * 4)
        throw Error(std::string(kernel) +
                    ": the temporary's rows must be padded to a multiple "
                    "of 4 floats");
}

}  // namespace mcd
