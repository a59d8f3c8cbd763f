// The caller's buffers as layers and outputs (include/mcdenoise/view.h): half conversion
// against the compiler's _Float16, views of every layout read into planar images and
// written back, frames of borrowed layers, and the views the library refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "harness/inputs.h"
#include "host/api/views.h"
#include "host/common/half.h"
#include "mcdenoise/error.h"
#include "mcdenoise/frame.h"

namespace mcd::test {
namespace {

uint32_t Bits(float f) {
    uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    return b;
}

uint16_t CompilerHalf(float f) {
    _Float16 h = static_cast<_Float16>(f);
    uint16_t b;
    std::memcpy(&b, &h, sizeof b);
    return b;
}

// Every half, to float, as the compiler converts it.
TEST(HalfFloat, EveryHalfToFloatIsTheCompilersValue) {
    for (uint32_t h = 0; h < 0x10000; ++h) {
        _Float16 half;
        uint16_t bits = uint16_t(h);
        std::memcpy(&half, &bits, sizeof half);
        float expected = float(half), got = HalfToFloat(bits);
        if (std::isnan(expected)) {
            EXPECT_TRUE(std::isnan(got)) << std::hex << h;
        } else {
            ASSERT_EQ(Bits(got), Bits(expected)) << std::hex << h;
        }
    }
}

// Floats to half round to nearest, ties to even, as the compiler does: every float whose
// bits are a multiple of a small prime apart (all exponents and many mantissas), the
// halfway points between neighbouring halves and the edges (65504, 65520, subnormals).
TEST(HalfFloat, FloatToHalfRoundsAsTheCompiler) {
    std::vector<float> values;
    for (uint64_t b = 0; b <= 0xffffffffull; b += 997) {
        float f;
        uint32_t bits = uint32_t(b);
        std::memcpy(&f, &bits, sizeof f);
        values.push_back(f);
    }
    for (uint32_t h = 0; h < 0x7c00; ++h) {
        float lo = HalfToFloat(uint16_t(h)), hi = HalfToFloat(uint16_t(h + 1));
        float mid = float((double(lo) + double(hi)) / 2);
        for (float v : {mid, std::nextafter(mid, 0.f), std::nextafter(mid, 1e9f)})
            values.insert(values.end(), {v, -v});
    }
    values.insert(values.end(), {65504.f, 65519.99f, 65520.f, 1e-8f, 2.98e-8f, 5.96e-8f,
                                 6.1e-5f, std::numeric_limits<float>::infinity(),
                                 std::numeric_limits<float>::denorm_min(), -0.f});
    for (float v : values) {
        uint16_t expected = CompilerHalf(v), got = FloatToHalf(v);
        if (std::isnan(v)) {
            EXPECT_TRUE(std::isnan(HalfToFloat(got)));
            EXPECT_EQ(got & 0x8000, expected & 0x8000);
        } else {
            ASSERT_EQ(got, expected) << v;
        }
    }
}

// One image, laid out in a caller's buffer in several ways, is read back bit for bit.
class ViewLayouts : public ::testing::Test {
  protected:
    const int w = 7, h = 5, c = 3;
    Image image = MakeInput(InputKind::Uniform, 7, 5, 3, 11);
};

TEST_F(ViewLayouts, InterleavedPlanarAndStridedReadBack) {
    std::vector<float> interleaved(size_t(w) * h * c), rgba(size_t(w) * h * 4, -1.f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k) {
                interleaved[(size_t(y) * w + x) * c + k] = image.At(k, y, x);
                rgba[(size_t(y) * w + x) * 4 + k] = image.At(k, y, x);
            }
    EXPECT_EQ(CopyView(LayerView::Interleaved(interleaved.data(), w, h, c)).data, image.data);
    EXPECT_EQ(CopyView(LayerView::Planar(image.data.data(), w, h, c)).data, image.data);
    // RGB out of RGBA: a pixel stride of four floats.
    LayerView rgb = LayerView::Interleaved(rgba.data(), w, h, 3, DataType::Float32, 16);
    EXPECT_EQ(CopyView(rgb).data, image.data);
    // All strides 0: packed interleaved.
    LayerView packed{interleaved.data(), w, h, c};
    EXPECT_EQ(CopyView(packed).data, image.data);
    // Bottom-up rows: a negative row stride from the last row.
    std::vector<float> flipped(interleaved.size());
    for (int y = 0; y < h; ++y)
        std::memcpy(&flipped[size_t(h - 1 - y) * w * c], &interleaved[size_t(y) * w * c],
                    size_t(w) * c * sizeof(float));
    LayerView up = LayerView::Interleaved(&flipped[size_t(h - 1) * w * c], w, h, c,
                                          DataType::Float32, 0, -std::ptrdiff_t(w * c * 4));
    EXPECT_EQ(CopyView(up).data, image.data);
}

TEST_F(ViewLayouts, HalfReadsAndWritesAsTheConversions) {
    std::vector<uint16_t> half(size_t(w) * h * c);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k)
                half[(size_t(y) * w + x) * c + k] = FloatToHalf(image.At(k, y, x));
    Image read = CopyView(LayerView::Interleaved(half.data(), w, h, c, DataType::Float16));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k)
                ASSERT_EQ(Bits(read.At(k, y, x)),
                          Bits(HalfToFloat(half[(size_t(y) * w + x) * c + k])));
    std::vector<uint16_t> written(half.size());
    api::WriteView(image, OutputView::Interleaved(written.data(), w, h, c, DataType::Float16));
    EXPECT_EQ(written, half);
}

TEST_F(ViewLayouts, WriteViewFillsOnlyItsChannels) {
    std::vector<float> rgba(size_t(w) * h * 4, -7.f);
    api::WriteView(image, OutputView::Interleaved(rgba.data(), w, h, 4));
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        EXPECT_EQ(rgba[i * 4 + 3], -7.f);
        for (int k = 0; k < c; ++k)
            EXPECT_EQ(rgba[i * 4 + k], image.data[size_t(k) * w * h + i]);
    }
}

ErrorKind KindOf(const std::function<void()> &call) {
    try {
        call();
    } catch (const Error &e) {
        return e.Kind();
    }
    ADD_FAILURE() << "no mcd::Error";
    return ErrorKind::Internal;
}

TEST(LibraryFrame, BorrowsViewsAndRefusesWhatDoesNotFit) {
    std::vector<float> rgb(6 * 4 * 3, 0.5f), other(5 * 4, 1.f);
    Frame frame;
    frame.SetLayer("color", LayerView::Interleaved(rgb.data(), 6, 4, 3));
    EXPECT_EQ(frame.width, 6);
    EXPECT_EQ(frame.height, 4);
    EXPECT_TRUE(frame.Has("color"));
    EXPECT_EQ(frame.Channels("color"), 3);
    rgb[0] = 2.f;  // borrowed, not copied
    EXPECT_EQ(frame.Copy("color").At(0, 0, 0), 2.f);
    EXPECT_EQ(
        KindOf([&] { frame.SetLayer("depth", LayerView::Interleaved(other.data(), 5, 4, 1)); }),
        ErrorKind::InvalidArgument);
    EXPECT_EQ(KindOf([&] {
                  frame.SetLayer("depth", LayerView{nullptr, 6, 4, 1});
              }),
              ErrorKind::InvalidArgument);
    EXPECT_EQ(KindOf([&] {
                  frame.SetLayer("depth", LayerView{other.data(), 6, 4, 0});
              }),
              ErrorKind::InvalidArgument);
    EXPECT_EQ(KindOf([&] { frame.Get("color"); }), ErrorKind::InvalidArgument);
    EXPECT_EQ(KindOf([&] { frame.Get("albedo"); }), ErrorKind::MissingLayer);
    frame.SetLayer("albedo", Image(6, 4, 3, 0.25f));
    EXPECT_EQ(frame.Names(), (std::vector<std::string>{"albedo", "color"}));
    frame.SetLayer("albedo", LayerView::Interleaved(rgb.data(), 6, 4, 3));
    EXPECT_EQ(frame.layers.count("albedo"), 0u);
}

}  // namespace
}  // namespace mcd::test
