// Images in the caller's memory: a renderer's buffers given to a frame as layers
// (LayerView) and a buffer a run writes its result into (OutputView), float32 or half,
// interleaved, planar or any other byte strides. Nothing here owns or copies memory.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mcd {

enum class DataType { Float32 = 1, Float16 = 2 };

inline size_t DataTypeBytes(DataType type) {
    return type == DataType::Float16 ? 2 : 4;
}

// Element (x, y, c) is at byte data + y * rowStride + x * pixelStride + c * channelStride.
// Strides may be negative (a flipped image). A stride of 0 takes its packed value:
// channelStride one element, pixelStride the pixel's channels when they are adjacent (else
// one element), rowStride a row of pixels; all three 0 is packed interleaved, [y][x][c].
template <class Pointer>
struct BasicView {
    Pointer data = nullptr;
    int width = 0, height = 0, channels = 0;
    DataType type = DataType::Float32;
    std::ptrdiff_t pixelStride = 0, rowStride = 0, channelStride = 0;

    // Packed interleaved, [y][x][c]; pixelStride > channels * element size skips the
    // channels after the first `channels` (RGB out of RGBA: channels 3, pixelStride 16).
    static BasicView Interleaved(Pointer data, int width, int height, int channels,
                                 DataType type = DataType::Float32,
                                 std::ptrdiff_t pixelStride = 0, std::ptrdiff_t rowStride = 0) {
        std::ptrdiff_t element = std::ptrdiff_t(DataTypeBytes(type));
        if (pixelStride == 0) pixelStride = element * channels;
        if (rowStride == 0) rowStride = pixelStride * width;
        return {data, width, height, channels, type, pixelStride, rowStride, element};
    }
    // Planar, [c][y][x] (the layout of mcd::Image and of the kernels).
    static BasicView Planar(Pointer data, int width, int height, int channels,
                            DataType type = DataType::Float32, std::ptrdiff_t rowStride = 0,
                            std::ptrdiff_t channelStride = 0) {
        std::ptrdiff_t element = std::ptrdiff_t(DataTypeBytes(type));
        if (rowStride == 0) rowStride = element * width;
        if (channelStride == 0) channelStride = rowStride * height;
        return {data, width, height, channels, type, element, rowStride, channelStride};
    }
    // The strides with the packed interleaved defaults filled in.
    BasicView Resolved() const {
        BasicView v = *this;
        std::ptrdiff_t element = std::ptrdiff_t(DataTypeBytes(type));
        if (v.channelStride == 0 && v.pixelStride == 0 && v.rowStride == 0)
            return Interleaved(data, width, height, channels, type);
        if (v.pixelStride == 0)
            v.pixelStride = v.channelStride == element ? element * channels : element;
        if (v.rowStride == 0) v.rowStride = v.pixelStride * width;
        if (v.channelStride == 0) v.channelStride = element;
        return v;
    }
};

// A layer the caller owns: borrowed by a Frame, read during each Method::Run on it.
using LayerView = BasicView<const void *>;
// A buffer the caller owns that a run writes its result into (RunOptions::output).
using OutputView = BasicView<void *>;

}  // namespace mcd
