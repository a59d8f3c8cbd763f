// host/vk: device listing and selection, the validation messenger, VkResult checking,
// buffers, the recorder's barrier tracking and timings, view checks and the kernel cache.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "cpu_reference/wavelet_analyze.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "harness/inputs.h"
#include "host/error.h"
#include "host/kernels/rhf_downsample.h"
#include "host/kernels/wavelet_analyze.h"
#include "host/kernels/wavelet_synthesize.h"
#include "host/vk/buffer.h"
#include "host/vk/build_pool.h"
#include "host/vk/check.h"
#include "host/vk/context.h"
#include "host/vk/gpu_image.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"
#include "rhf/downsample.h"
#include "wavelet/lines.h"

namespace mcd::test {
namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
    for (char &c : s) c = char(std::tolower((unsigned char)c));
    return s;
}

// The lavapipe device, if the loader sees one.
std::optional<vk::DeviceInfo> Lavapipe(const std::vector<vk::DeviceInfo> &devices) {
    for (const vk::DeviceInfo &d : devices)
        if (Contains(Lower(d.name), "llvmpipe")) return d;
    return std::nullopt;
}

// Sets (or unsets, for nullopt) an environment variable for the guard's lifetime.
class EnvGuard {
  public:
    EnvGuard(const char *name, std::optional<std::string> value) : name(name) {
        if (const char *old = std::getenv(name)) saved = old;
        if (value)
            setenv(name, value->c_str(), 1);
        else
            unsetenv(name);
    }
    ~EnvGuard() {
        if (saved)
            setenv(name, saved->c_str(), 1);
        else
            unsetenv(name);
    }
    EnvGuard(const EnvGuard &) = delete;
    EnvGuard &operator=(const EnvGuard &) = delete;

  private:
    const char *name;
    std::optional<std::string> saved;
};

// ---------------------------------------------------------------------------------------
// Devices

class VkDevices : public ::testing::Test {};

TEST_F(VkDevices, ListHasAComputeDeviceWithNames) {
    std::vector<vk::DeviceInfo> devices = vk::ListDevices();
    ASSERT_FALSE(devices.empty());
    bool anyCompute = false;
    for (size_t i = 0; i < devices.size(); ++i) {
        EXPECT_EQ(devices[i].index, int(i));
        EXPECT_FALSE(devices[i].name.empty()) << "device " << i;
        anyCompute |= devices[i].hasCompute;
    }
    EXPECT_TRUE(anyCompute);
    // The listing must be stable: a second call sees the same devices.
    std::vector<vk::DeviceInfo> again = vk::ListDevices();
    ASSERT_EQ(again.size(), devices.size());
    for (size_t i = 0; i < devices.size(); ++i) EXPECT_EQ(again[i].name, devices[i].name);
}

TEST_F(VkDevices, TypeNames) {
    EXPECT_STREQ(vk::DeviceTypeName(VK_PHYSICAL_DEVICE_TYPE_CPU), "CPU");
    EXPECT_STREQ(vk::DeviceTypeName(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU), "discrete GPU");
    EXPECT_STREQ(vk::DeviceTypeName(VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU), "integrated GPU");
    EXPECT_STREQ(vk::DeviceTypeName(VK_PHYSICAL_DEVICE_TYPE_OTHER), "other");
    std::optional<vk::DeviceInfo> lavapipe = Lavapipe(vk::ListDevices());
    if (!lavapipe) GTEST_SKIP() << "no lavapipe device";
    EXPECT_EQ(lavapipe->type, VK_PHYSICAL_DEVICE_TYPE_CPU);
    EXPECT_STREQ(vk::DeviceTypeName(lavapipe->type), "CPU");
    EXPECT_TRUE(lavapipe->hasCompute);
}

TEST_F(VkDevices, SelectByIndex) {
    EnvGuard env("MCD_DEVICE", std::nullopt);
    std::vector<vk::DeviceInfo> devices = vk::ListDevices();
    ASSERT_FALSE(devices.empty());
    if (!devices[0].hasCompute) GTEST_SKIP() << "device 0 has no compute queue";
    vk::Context context(vk::ContextOptions{.device = "0"});
    EXPECT_EQ(context.Info().index, 0);
    EXPECT_EQ(context.Info().name, devices[0].name);
    EXPECT_NE(context.Device(), VK_NULL_HANDLE);
    EXPECT_FALSE(context.ValidationEnabled());
}

TEST_F(VkDevices, SelectByNameIsCaseInsensitiveSubstring) {
    EnvGuard env("MCD_DEVICE", std::nullopt);
    std::optional<vk::DeviceInfo> lavapipe = Lavapipe(vk::ListDevices());
    if (!lavapipe) GTEST_SKIP() << "no lavapipe device";
    for (const char *selector : {"llvmpipe", "LLVMPIPE", "LlvmPipe"}) {
        vk::Context context(vk::ContextOptions{.device = selector});
        EXPECT_EQ(context.Info().index, lavapipe->index) << selector;
        EXPECT_EQ(context.Info().name, lavapipe->name) << selector;
    }
}

TEST_F(VkDevices, BadSelectorsThrowAndListTheDevices) {
    EnvGuard env("MCD_DEVICE", std::nullopt);
    std::vector<vk::DeviceInfo> devices = vk::ListDevices();
    bool lavapipe = Lavapipe(devices).has_value();
    for (const char *selector : {"no-such-gpu", "99"}) {
        std::string message =
            ErrorOf([&] { vk::Context context(vk::ContextOptions{.device = selector}); });
        EXPECT_FALSE(Contains(message, "<no error>")) << selector;
        EXPECT_FALSE(Contains(message, "<not an mcd::Error")) << selector << ": " << message;
        for (const vk::DeviceInfo &d : devices)
            EXPECT_TRUE(Contains(message, d.name)) << selector << ": " << message;
        if (lavapipe) {
            EXPECT_TRUE(Contains(message, "llvmpipe")) << selector << ": " << message;
        }
        EXPECT_TRUE(Contains(message, selector)) << message;
        EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] {
            vk::Context context(vk::ContextOptions{.device = selector});
        }));
    }
}

TEST_F(VkDevices, EnvironmentSelectsWhenOptionIsEmpty) {
    {
        // A bad $MCD_DEVICE must be honoured (and so fail) when options.device is empty...
        EnvGuard env("MCD_DEVICE", "no-such-gpu");
        EXPECT_TRUE(ThrowsError(
            ErrorKind::InvalidArgument, [] { vk::Context context; }, "no-such-gpu"));
        // ...and ignored when options.device names one.
        vk::Context context(vk::ContextOptions{.device = "0"});
        EXPECT_EQ(context.Info().index, 0);
    }
    std::optional<vk::DeviceInfo> lavapipe = Lavapipe(vk::ListDevices());
    if (!lavapipe) GTEST_SKIP() << "no lavapipe device";
    EnvGuard env("MCD_DEVICE", "LLVMpipe");
    vk::Context context;
    EXPECT_EQ(context.Info().index, lavapipe->index);
}

// ---------------------------------------------------------------------------------------
// Validation messages

class VkValidation : public GpuTest {};

// A buffer with no usage bits is invalid (VUID-VkBufferCreateInfo-usage-requiredbitmask)
// but harmless to the driver.
void CreateBufferWithoutUsage(vk::Context &context) {
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = 256;
    bi.usage = 0;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkResult result = vkCreateBuffer(context.Device(), &bi, nullptr, &buffer);
    if (result == VK_SUCCESS && buffer != VK_NULL_HANDLE)
        vkDestroyBuffer(context.Device(), buffer, nullptr);
}

TEST_F(VkValidation, InvalidCallIsReported) {
    ASSERT_TRUE(Ctx().ValidationEnabled());
    EXPECT_TRUE(Ctx().TakeValidationMessages().empty());
    CreateBufferWithoutUsage(Ctx());
    std::vector<std::string> messages = Ctx().TakeValidationMessages();
    ASSERT_FALSE(messages.empty()) << "the validation layer reported nothing";
    bool relevant = false;
    for (const std::string &m : messages)
        relevant |= Contains(m, "VkBufferCreateInfo") && Contains(m, "usage");
    EXPECT_TRUE(relevant) << messages.front();
    EXPECT_TRUE(Contains(messages.front(), "validation error")) << messages.front();
    // Taken means gone.
    EXPECT_TRUE(Ctx().TakeValidationMessages().empty());
}

// Other contexts (their own instance and device) and ListDevices() must not take the
// shared context's validation away: entry points are loaded once per process as loader
// trampolines, which dispatch on the handle.
TEST_F(VkValidation, StillReportedAfterAnotherContext) {
    {
        EnvGuard env("MCD_DEVICE", std::nullopt);
        vk::Context other;
        vk::Buffer buffer(other, 64, "other");
        EXPECT_TRUE(buffer.Valid());
        (void)vk::ListDevices();
    }
    CreateBufferWithoutUsage(Ctx());
    EXPECT_FALSE(Ctx().TakeValidationMessages().empty())
        << "validation went silent after another context was created";
}

// ListDevices() makes a temporary instance without VK_EXT_debug_utils while a validated
// Context lives; the Context must still tear its messenger down. Run in a child process,
// since the failure mode is a crash.
TEST(VkDevicesDeathTest, ListDevicesWhileAValidatedContextLives) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(
        {
            {
                vk::Context context(vk::ContextOptions{.validation = true});
                (void)vk::ListDevices();
                vk::Buffer buffer(context, 64, "after");
                buffer.UploadFloats({1.f});
            }
            std::_Exit(0);
        },
        ::testing::ExitedWithCode(0), "");
}

// ---------------------------------------------------------------------------------------
// VkResult checking

VkResult FailWithOutOfDeviceMemory() {
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
}

TEST(VkCheck, ThrowVkErrorNamesCallResultFileAndLine) {
    std::string message = ErrorOf([] {
        vk::ThrowVkError(VK_ERROR_DEVICE_LOST, "vkQueueSubmit(queue)", "some/file.cpp", 4321);
    });
    EXPECT_TRUE(Contains(message, "vkQueueSubmit(queue)")) << message;
    EXPECT_TRUE(Contains(message, "VK_ERROR_DEVICE_LOST")) << message;
    EXPECT_TRUE(Contains(message, "some/file.cpp")) << message;
    EXPECT_TRUE(Contains(message, "4321")) << message;
}

// Memory exhaustion is its own kind; every other failed call is the device's.
TEST(VkCheck, ThrowVkErrorGivesTheKind) {
    for (VkResult memory : {VK_ERROR_OUT_OF_HOST_MEMORY, VK_ERROR_OUT_OF_DEVICE_MEMORY})
        EXPECT_TRUE(ThrowsError(ErrorKind::OutOfMemory, [&] {
            vk::ThrowVkError(memory, "vkAllocateMemory", "f", 1);
        })) << vk::ResultName(memory);
    for (VkResult other : {VK_ERROR_DEVICE_LOST, VK_ERROR_INITIALIZATION_FAILED,
                           VK_ERROR_FRAGMENTED_POOL, VK_ERROR_UNKNOWN})
        EXPECT_TRUE(ThrowsError(ErrorKind::Device, [&] {
            vk::ThrowVkError(other, "vkQueueSubmit", "f", 1);
        })) << vk::ResultName(other);
}

TEST(VkCheck, MacroThrowsWithTheCallSite) {
    auto failing = [] { return VK_ERROR_OUT_OF_DEVICE_MEMORY; };
    int line = 0;
    std::string message = ErrorOf([&] {
        line = __LINE__ + 1;
        MCD_VK(failing());
    });
    EXPECT_TRUE(Contains(message, "failing()")) << message;
    EXPECT_TRUE(Contains(message, "VK_ERROR_OUT_OF_DEVICE_MEMORY")) << message;
    EXPECT_TRUE(Contains(message, fs::path(__FILE__).filename().string())) << message;
    EXPECT_TRUE(Contains(message, ":" + std::to_string(line))) << message;

    message = ErrorOf([] { MCD_VK(FailWithOutOfDeviceMemory()); });
    EXPECT_TRUE(Contains(message, "FailWithOutOfDeviceMemory()")) << message;
    EXPECT_TRUE(Contains(message, "VK_ERROR_OUT_OF_DEVICE_MEMORY")) << message;
    EXPECT_TRUE(
        ThrowsError(ErrorKind::OutOfMemory, [] { MCD_VK(FailWithOutOfDeviceMemory()); }));
}

TEST(VkCheck, MacroEvaluatesOnceAndPassesSuccess) {
    int calls = 0;
    auto ok = [&] {
        ++calls;
        return VK_SUCCESS;
    };
    EXPECT_NO_THROW(MCD_VK(ok()));
    EXPECT_EQ(calls, 1);
    auto failing = [&] {
        ++calls;
        return VK_ERROR_DEVICE_LOST;
    };
    // A single statement, so it nests in an unbraced if/else.
    auto either = [&](bool fail) {
        if (fail)
            MCD_VK(failing());
        else
            MCD_VK(ok());
    };
    EXPECT_TRUE(ThrowsError(ErrorKind::Device, [&] { either(true); }));
    EXPECT_NO_THROW(either(false));
    EXPECT_EQ(calls, 3);
    EXPECT_STREQ(vk::ResultName(VK_SUCCESS), "VK_SUCCESS");
    EXPECT_STREQ(vk::ResultName(VK_ERROR_OUT_OF_HOST_MEMORY), "VK_ERROR_OUT_OF_HOST_MEMORY");
}

// ---------------------------------------------------------------------------------------
// Buffers

class VkBuffer_ : public GpuTest {};

std::vector<uint32_t> RandomBits(size_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<uint32_t> bits(count);
    for (uint32_t &b : bits) b = rng();
    return bits;
}

TEST_F(VkBuffer_, RoundTripIsBitExact) {
    // Random bit patterns: NaN payloads, denormals and negative zero included.
    std::vector<uint32_t> bits = RandomBits(4099, 1);
    bits[0] = 0x7fc00001u;  // quiet NaN with a payload
    bits[1] = 0x80000000u;  // -0
    bits[2] = 0x00000001u;  // smallest denormal
    std::vector<float> values(bits.size());
    std::memcpy(values.data(), bits.data(), bits.size() * sizeof(float));
    vk::Buffer buffer(Ctx(), values.size() * sizeof(float), "roundtrip");
    EXPECT_TRUE(buffer.Valid());
    EXPECT_EQ(buffer.Bytes(), values.size() * sizeof(float));
    EXPECT_EQ(buffer.Name(), "roundtrip");
    buffer.UploadFloats(values);
    std::vector<float> back = buffer.DownloadFloats(values.size());
    ASSERT_EQ(back.size(), values.size());
    EXPECT_EQ(std::memcmp(back.data(), values.data(), values.size() * sizeof(float)), 0);
}

TEST_F(VkBuffer_, OffsetUploadAndDownload) {
    const size_t n = 64;
    vk::Buffer buffer(Ctx(), n * sizeof(float), "offsets");
    std::vector<float> base(n);
    for (size_t i = 0; i < n; ++i) base[i] = float(i);
    buffer.UploadFloats(base);
    // Overwrite floats 10..14 through a byte offset, then read pieces back.
    std::vector<float> patch = {-1.f, -2.f, -3.f, -4.f, -5.f};
    buffer.Upload(patch.data(), patch.size() * sizeof(float), 10 * sizeof(float));
    std::vector<float> expected = base;
    std::copy(patch.begin(), patch.end(), expected.begin() + 10);
    EXPECT_EQ(buffer.DownloadFloats(n), expected);
    EXPECT_EQ(buffer.DownloadFloats(7, 8),
              std::vector<float>(expected.begin() + 8, expected.begin() + 15));
    // The last element, exactly at the end.
    EXPECT_EQ(buffer.DownloadFloats(1, n - 1), std::vector<float>{float(n - 1)});
    // An unaligned byte offset.
    uint8_t byte = 0;
    buffer.Download(&byte, 1, 10 * sizeof(float) + 3);
    uint32_t minusOne;
    std::memcpy(&minusOne, &patch[0], 4);
    EXPECT_EQ(byte, uint8_t(minusOne >> 24));
}

TEST_F(VkBuffer_, OverrunsThrow) {
    vk::Buffer buffer(Ctx(), 16, "small");
    std::vector<uint8_t> data(32, 0xab);
    EXPECT_NO_THROW(buffer.Upload(data.data(), 16));
    EXPECT_NO_THROW(buffer.Upload(data.data(), 4, 12));
    EXPECT_NO_THROW(buffer.Download(data.data(), 16));
    // A caller's bug, naming the buffer.
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Internal, [&] { buffer.Upload(data.data(), 17); }, "small"));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] { buffer.Upload(data.data(), 4, 13); }));
    EXPECT_TRUE(ThrowsError(
        ErrorKind::Internal, [&] { buffer.Download(data.data(), 17); }, "small"));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] { buffer.Download(data.data(), 1, 16); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] { buffer.DownloadFloats(5); }));
    EXPECT_TRUE(
        ThrowsError(ErrorKind::Internal, [&] { buffer.UploadFloats(std::vector<float>(5)); }));
    // The failed uploads wrote nothing.
    std::vector<uint8_t> back(16);
    buffer.Download(back.data(), 16);
    EXPECT_EQ(back, std::vector<uint8_t>(16, 0xab));
}

TEST_F(VkBuffer_, ZeroBytes) {
    vk::Buffer empty(Ctx(), 0, "empty");
    EXPECT_TRUE(empty.Valid());
    EXPECT_EQ(empty.Bytes(), 0u);
    EXPECT_NO_THROW(empty.Upload(nullptr, 0));
    EXPECT_NO_THROW(empty.Download(nullptr, 0));
    EXPECT_TRUE(empty.DownloadFloats(0).empty());
    float x = 1.f;
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] { empty.Upload(&x, sizeof x); }));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] { empty.Download(&x, sizeof x); }));
}

TEST_F(VkBuffer_, MoveLeavesSourceInvalid) {
    vk::Buffer a(Ctx(), 8 * sizeof(float), "a");
    std::vector<float> values = {1, 2, 3, 4, 5, 6, 7, 8};
    a.UploadFloats(values);
    VkBuffer handle = a.Handle();

    vk::Buffer b(std::move(a));
    EXPECT_FALSE(a.Valid());
    EXPECT_EQ(a.Handle(), VK_NULL_HANDLE);
    EXPECT_EQ(a.Bytes(), 0u);
    EXPECT_TRUE(b.Valid());
    EXPECT_EQ(b.Handle(), handle);
    EXPECT_EQ(b.Bytes(), 8 * sizeof(float));
    EXPECT_EQ(b.Name(), "a");
    EXPECT_EQ(b.DownloadFloats(8), values);
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] { a.DownloadFloats(1); }));

    vk::Buffer c(Ctx(), 4, "c");
    c = std::move(b);
    EXPECT_FALSE(b.Valid());
    EXPECT_EQ(b.Bytes(), 0u);
    EXPECT_EQ(c.Handle(), handle);
    EXPECT_EQ(c.Name(), "a");
    EXPECT_EQ(c.DownloadFloats(8), values);
    std::vector<float> more = {9, 10, 11, 12, 13, 14, 15, 16};
    c.UploadFloats(more);
    EXPECT_EQ(c.DownloadFloats(8), more);

    // Assigning into a default-constructed buffer, and a moved-from one being reused.
    vk::Buffer d;
    EXPECT_FALSE(d.Valid());
    d = std::move(c);
    EXPECT_EQ(d.DownloadFloats(8), more);
    a = vk::Buffer(Ctx(), 4, "reborn");
    EXPECT_TRUE(a.Valid());
    EXPECT_EQ(a.Name(), "reborn");
}

// ---------------------------------------------------------------------------------------
// Recorder

class VkRecorder : public GpuTest {};

constexpr int kW = 16, kH = 16, kC = 1;

Image Input(uint64_t seed) {
    return MakeInput(InputKind::Uniform, kW, kH, kC, seed);
}

Tolerance WaveletTol() {
    return {200 * 0x1p-24, 0, 1e-9};
}

TEST_F(VkRecorder, IndependentDispatchesNeedNoBarrier) {
    Image in1 = Input(1), in2 = Input(2);
    vk::GpuImage src1(Ctx(), kW, kH, kC, "src1"), coef1(Ctx(), kW, kH, kC, "coef1");
    vk::GpuImage src2(Ctx(), kW, kH, kC, "src2"), coef2(Ctx(), kW, kH, kC, "coef2");
    vk::GpuImage tmp1(Ctx(), kW, kH, kC, "tmp1"), tmp2(Ctx(), kW, kH, kC, "tmp2");
    src1.Upload(in1);
    src2.Upload(in2);
    vk::Recorder recorder(Ctx());
    // Each analysis is a rows pass into its temporary and a columns pass out of it: one
    // barrier inside each, none between the two.
    RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::Cdf97, kW, kH, kC, src1.View(),
                         tmp1.MutableView(), coef1.MutableView(), "first");
    EXPECT_EQ(recorder.BarrierCount(), 1u);
    RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::Cdf97, kW, kH, kC, src2.View(),
                         tmp2.MutableView(), coef2.MutableView(), "second");
    EXPECT_EQ(recorder.DispatchCount(), 4u);
    EXPECT_EQ(recorder.BarrierCount(), 2u);
    recorder.Submit();
    EXPECT_TRUE(ImagesMatch(ref::WaveletAnalyze(in1, WaveletBasis::Cdf97, 1), coef1.Download(),
                            ref::WaveletAnalyzeMagnitude(in1, WaveletBasis::Cdf97, 1),
                            WaveletTol()));
    EXPECT_TRUE(ImagesMatch(ref::WaveletAnalyze(in2, WaveletBasis::Cdf97, 1), coef2.Download(),
                            ref::WaveletAnalyzeMagnitude(in2, WaveletBasis::Cdf97, 1),
                            WaveletTol()));

    // Timings: one per dispatch, in order, with the labels given.
    const std::vector<vk::DispatchTiming> &timings = recorder.Timings();
    ASSERT_EQ(timings.size(), 4u);
    EXPECT_EQ(timings[0].label, "first.rows");
    EXPECT_EQ(timings[1].label, "first.columns");
    EXPECT_EQ(timings[2].label, "second.rows");
    EXPECT_EQ(timings[3].label, "second.columns");
    for (const vk::DispatchTiming &t : timings) {
        if (Ctx().Info().timestamps)
            EXPECT_GE(t.gpuMs, 0) << t.label;
        else
            EXPECT_LT(t.gpuMs, 0) << t.label;
    }
    EXPECT_GE(recorder.TotalGpuMs(), 0);
    if (Lavapipe({Ctx().Info()})) {
        EXPECT_TRUE(Ctx().Info().timestamps);
    }
}

TEST_F(VkRecorder, ReadAfterWriteGetsOneBarrier) {
    Image in = Input(3);
    vk::GpuImage src(Ctx(), kW, kH, kC, "src"), coef(Ctx(), kW, kH, kC, "coef"),
        out(Ctx(), kW, kH, kC, "out"), tmp(Ctx(), kW, kH, kC, "tmp");
    src.Upload(in);
    vk::Recorder recorder(Ctx());
    RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::LeGall53, kW, kH, kC, src.View(),
                         tmp.MutableView(), coef.MutableView(), "analyze");
    EXPECT_EQ(recorder.BarrierCount(), 1u);  // rows -> tmp -> columns
    // Synthesis reads coef (just written) and rewrites tmp (just read): one barrier before
    // its columns pass, one between its passes.
    RecordWaveletSynthesize(Ctx(), recorder, WaveletBasis::LeGall53, kW, kH, kC, coef.View(),
                            tmp.MutableView(), out.MutableView(), "synthesize");
    EXPECT_EQ(recorder.BarrierCount(), 3u);
    recorder.Submit();
    EXPECT_EQ(recorder.BarrierCount(), 3u);
    Image back = out.Download();
    EXPECT_TRUE(ImagesMatch(in, back, Image(), {0, 1e-5, 1e-9}));
    ASSERT_EQ(recorder.Timings().size(), 4u);
    EXPECT_EQ(recorder.Timings()[0].label, "analyze.rows");
    EXPECT_EQ(recorder.Timings()[3].label, "synthesize.rows");
}

TEST_F(VkRecorder, WriteAfterReadAndCopiesAreOrdered) {
    Image in = Input(4);
    vk::GpuImage a(Ctx(), kW, kH, kC, "a"), b(Ctx(), kW, kH, kC, "b"),
        c(Ctx(), kW, kH, kC, "c"), d(Ctx(), kW, kH, kC, "d"), t(Ctx(), kW, kH, kC, "t"),
        u(Ctx(), kW, kH, kC, "u");
    a.Upload(in);
    vk::Recorder recorder(Ctx());
    // Copy a -> b, analyze b -> c (its rows pass reads what the copy wrote: barrier; its
    // columns pass reads its rows pass's output: barrier).
    recorder.Copy(a.buffer, b.buffer, a.buffer.Bytes());
    EXPECT_EQ(recorder.BarrierCount(), 0u);
    RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::Haar, kW, kH, kC, b.View(),
                         t.MutableView(), c.MutableView(), "analyze");
    EXPECT_EQ(recorder.BarrierCount(), 2u);
    // Overwrite b: its reader (the rows pass) is already behind the analysis's own
    // rows -> columns barrier, so the copy needs none.
    recorder.Copy(a.buffer, b.buffer, a.buffer.Bytes() / 2);
    EXPECT_EQ(recorder.BarrierCount(), 2u);
    // Write c again through another temporary: the rows pass (reads a, writes u) needs no
    // barrier, the columns pass reads u and rewrites c: one.
    RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::Haar, kW, kH, kC, a.View(),
                         u.MutableView(), d.MutableView(), "again");
    EXPECT_EQ(recorder.BarrierCount(), 3u);
    // Reading b (its copy is behind the barrier inside "again") through t (last read before
    // barrier 2): only the analysis's own barrier.
    RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::Haar, kW, kH, kC, b.View(),
                         t.MutableView(), c.MutableView(), "third");
    EXPECT_EQ(recorder.BarrierCount(), 4u);
    recorder.Submit();
    EXPECT_EQ(recorder.DispatchCount(), 6u);
    EXPECT_TRUE(BitIdentical(c.Download(), d.Download()));
    EXPECT_TRUE(ImagesMatch(ref::WaveletAnalyze(in, WaveletBasis::Haar, 1), c.Download(),
                            ref::WaveletAnalyzeMagnitude(in, WaveletBasis::Haar, 1),
                            WaveletTol()));
    EXPECT_TRUE(BitIdentical(in, b.Download()));
}

TEST_F(VkRecorder, ReusableAfterSubmit) {
    Image in = Input(5);
    vk::GpuImage src(Ctx(), kW, kH, kC, "src"), coef(Ctx(), kW, kH, kC, "coef"),
        tmp(Ctx(), kW, kH, kC, "tmp");
    src.Upload(in);
    vk::Recorder recorder(Ctx());
    std::vector<Image> results;
    for (int run = 0; run < 3; ++run) {
        coef.Upload(Image(kW, kH, kC, float(run) + 7.f));
        RecordWaveletAnalyze(Ctx(), recorder, WaveletBasis::Cdf97, kW, kH, kC, src.View(),
                             tmp.MutableView(), coef.MutableView(), "run");
        EXPECT_EQ(recorder.DispatchCount(), 2u) << "run " << run;
        EXPECT_EQ(recorder.BarrierCount(), 1u) << "run " << run;
        recorder.Submit();
        EXPECT_EQ(recorder.Timings().size(), 2u) << "run " << run;
        results.push_back(coef.Download());
    }
    EXPECT_TRUE(BitIdentical(results[0], results[1]));
    EXPECT_TRUE(BitIdentical(results[0], results[2]));
    // Submitting with nothing recorded is a no-op that clears the timings.
    recorder.Submit();
    EXPECT_TRUE(recorder.Timings().empty());
    EXPECT_EQ(recorder.TotalGpuMs(), 0);
}

// A kernel's SPIR-V, read from the build tree (the embedded arrays' headers are private
// to mcd_kernels): <build>/tests/mcd_tests -> <build>/shaders/<path>; empty if missing.
std::vector<uint32_t> BuiltSpirv(const std::string &path) {
    std::vector<uint32_t> words;
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return words;
    std::ifstream file(exe.parent_path().parent_path() / "shaders" / path, std::ios::binary);
    if (!file) return words;
    std::string bytes((std::istreambuf_iterator<char>(file)), {});
    words.resize(bytes.size() / 4);
    std::memcpy(words.data(), bytes.data(), words.size() * 4);
    return words;
}

const std::vector<uint32_t> *AnalyzeSpirv() {
    static const std::vector<uint32_t> code = BuiltSpirv("wavelet/analyze.spv");
    return code.empty() ? nullptr : &code;
}

vk::KernelDesc AnalyzeDesc(const std::vector<uint32_t> &code, WaveletBasis basis) {
    return {"wavelet_analyze",
            code.data(),
            code.size() * sizeof(uint32_t),
            WAVELET_LINES_BINDINGS,
            sizeof(shader::WaveletLinesPush),
            {{0, int32_t(basis)}}};
}

TEST_F(VkRecorder, DispatchLimitsThrow) {
    const std::vector<uint32_t> *code = AnalyzeSpirv();
    ASSERT_NE(code, nullptr) << "analyze.spv not found next to the test binary's build tree";
    const vk::Kernel &kernel = Ctx().GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar));
    vk::Buffer a(Ctx(), 256, "a"), b(Ctx(), 256, "b");
    shader::WaveletLinesPush push{};
    std::vector<vk::Binding> bindings = {{WAVELET_LINES_SRC, &a, vk::Access::Read},
                                         {WAVELET_LINES_DST, &b, vk::Access::Write}};
    vk::Recorder recorder(Ctx());
    const VkPhysicalDeviceLimits &limits = Ctx().Limits();
    for (int axis = 0; axis < 3; ++axis) {
        uint32_t groups[3] = {1, 1, 1};
        if (limits.maxComputeWorkGroupCount[axis] == UINT32_MAX) continue;
        groups[axis] = limits.maxComputeWorkGroupCount[axis] + 1;
        // Too large for this device, naming the dispatch.
        EXPECT_TRUE(ThrowsError(
            ErrorKind::OutOfMemory,
            [&] {
                recorder.Dispatch(kernel, "huge", bindings, push, groups[0], groups[1],
                                  groups[2]);
            },
            "huge"));
    }
    std::string message =
        ErrorOf([&] { recorder.Dispatch(kernel, "short", {bindings[0]}, push, 1); });
    EXPECT_TRUE(Contains(message, "wavelet_analyze")) << message;
    EXPECT_TRUE(Contains(message, "short")) << message;
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        recorder.Dispatch(kernel, "short", {bindings[0]}, push, 1);
    }));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        recorder.Dispatch(kernel, "long", {bindings[0], bindings[1], bindings[1]}, push, 1);
    }));
    vk::Buffer invalid;
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        recorder.Dispatch(kernel, "unbound",
                          {bindings[0], {WAVELET_LINES_DST, &invalid, vk::Access::Write}}, push,
                          1);
    }));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        recorder.Dispatch(kernel, "null",
                          {bindings[0], {WAVELET_LINES_DST, nullptr, vk::Access::Write}}, push,
                          1);
    }));
    // Slots are the layout header's names: one bound twice, one the kernel does not
    // declare, or push constants of the wrong size are refused, naming the kernel and slot.
    message = ErrorOf([&] {
        recorder.Dispatch(kernel, "twice",
                          {bindings[0], {WAVELET_LINES_SRC, &b, vk::Access::Write}}, push, 1);
    });
    EXPECT_TRUE(Contains(message, "wavelet_analyze")) << message;
    EXPECT_TRUE(Contains(message, "slot 0")) << message;
    message = ErrorOf([&] {
        recorder.Dispatch(
            kernel, "beyond",
            {bindings[0], bindings[1], {WAVELET_LINES_BINDINGS, &b, vk::Access::Read}}, push,
            1);
    });
    EXPECT_TRUE(Contains(message, "wavelet_analyze")) << message;
    EXPECT_TRUE(Contains(message, "slot 2")) << message;
    struct Longer {
        shader::WaveletLinesPush lines;
        float extra;
    };
    message = ErrorOf([&] {
        recorder.Dispatch(kernel, "push", bindings, Longer{push, 0.f}, 1);
    });
    EXPECT_TRUE(Contains(message, "wavelet_analyze")) << message;
    EXPECT_TRUE(Contains(message, "push constants")) << message;
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        recorder.Dispatch(kernel, "push", bindings, Longer{push, 0.f}, 1);
    }));
    EXPECT_EQ(recorder.DispatchCount(), 0u);
    // The rejected dispatches left the recorder usable.
    push = {4, 4, 4, 16, 4, 16};
    recorder.Dispatch(kernel, "fine", bindings, push, 1);
    recorder.Submit();
    ASSERT_EQ(recorder.Timings().size(), 1u);
    EXPECT_EQ(recorder.Timings()[0].label, "fine");
    // The order of the bindings does not matter, their slots do.
    recorder.Dispatch(kernel, "swapped", {bindings[1], bindings[0]}, push, 1);
    recorder.Submit();
    ASSERT_EQ(recorder.Timings().size(), 1u);
    EXPECT_EQ(recorder.Timings()[0].label, "swapped");
}

// ---------------------------------------------------------------------------------------
// View checks

class VkView : public GpuTest {};

TEST_F(VkView, FittingViewsPass) {
    // Exactly enough: the last row needs only `width` of its stride.
    vk::Buffer exact(Ctx(), ((2 - 1) * 40 + (3 - 1) * 12 + 10) * sizeof(float), "exact");
    EXPECT_NO_THROW(vk::CheckView({&exact, 12, 40}, 10, 3, 2, "probe"));
    vk::GpuImage image(Ctx(), 5, 4, 3, "image");
    EXPECT_NO_THROW(vk::CheckView(image.View(), 5, 4, 3, "probe"));
    EXPECT_NO_THROW(vk::CheckView(image.View(), 3, 2, 3, "probe"));  // a sub-region
}

TEST_F(VkView, TooSmallBufferThrowsNamingIt) {
    vk::Buffer tiny(Ctx(), (16 * 16 - 1) * sizeof(float), "tiny-buffer");
    std::string message = ErrorOf([&] {
        vk::CheckView({&tiny, 16, 256}, 16, 16, 1, "probe view");
    });
    EXPECT_TRUE(Contains(message, "tiny-buffer")) << message;
    EXPECT_TRUE(Contains(message, "probe view")) << message;
    vk::GpuImage image(Ctx(), 8, 8, 2, "two-channel");
    message = ErrorOf([&] { vk::CheckView(image.View(), 8, 8, 3, "channels"); });
    EXPECT_TRUE(Contains(message, "two-channel")) << message;
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal,
                            [&] { vk::CheckView(image.View(), 8, 8, 3, "channels"); }));
}

TEST_F(VkView, BadStrideOrPlaneThrows) {
    vk::Buffer big(Ctx(), 4096 * sizeof(float), "big");
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        vk::CheckView({&big, 8, 256}, 16, 16, 1, "stride");
    }));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        vk::CheckView({&big, 16, 100}, 16, 16, 2, "plane");
    }));
    // One channel: the plane does not matter.
    EXPECT_NO_THROW(vk::CheckView({&big, 16, 0}, 16, 16, 1, "one channel"));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        vk::CheckView({nullptr, 16, 256}, 16, 16, 1, "null");
    }));
    vk::Buffer invalid;
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        vk::CheckView({&invalid, 16, 256}, 16, 16, 1, "invalid");
    }));
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        vk::CheckView({&big, 16, 256}, 0, 16, 1, "empty");
    }));
}

// ---------------------------------------------------------------------------------------
// Kernel cache

class VkKernelCache : public GpuTest {};

TEST_F(VkKernelCache, SameDescSameKernel) {
    const std::vector<uint32_t> *code = AnalyzeSpirv();
    ASSERT_NE(code, nullptr) << "analyze.spv not found next to the test binary's build tree";
    const vk::Kernel &haar = Ctx().GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar));
    const vk::Kernel &again = Ctx().GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar));
    EXPECT_EQ(&haar, &again);
    EXPECT_EQ(haar.Pipeline(), again.Pipeline());
    const vk::Kernel &cdf = Ctx().GetKernel(AnalyzeDesc(*code, WaveletBasis::Cdf97));
    EXPECT_NE(&haar, &cdf);
    EXPECT_NE(haar.Pipeline(), cdf.Pipeline());
    EXPECT_EQ(haar.Name(), "wavelet_analyze");
    EXPECT_EQ(haar.BindingCount(), uint32_t(WAVELET_LINES_BINDINGS));
    EXPECT_EQ(haar.PushBytes(), sizeof(shader::WaveletLinesPush));
    // The cached kernel is still the first one after another was added.
    EXPECT_EQ(&Ctx().GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar)), &haar);
    EXPECT_NE(vk::KernelKey(AnalyzeDesc(*code, WaveletBasis::Haar)),
              vk::KernelKey(AnalyzeDesc(*code, WaveletBasis::Cdf97)));
}

// ---------------------------------------------------------------------------------------
// Texel-buffer bindings

class VkTexelRecorder : public GpuTest {};

// A kernel reading its source through a texel view sees the buffer's floats exactly: a
// one-tap "downsampling" by 1 with weight 1 copies them (x * 1 is exact for every finite
// float; denormals are left out, as a GPU may flush them on fetch).
TEST_F(VkTexelRecorder, TexelViewsReadTheBufferExactly) {
    const int w = 37, h = 5, planes = 2;
    std::mt19937 rng(SeedFromName("texel view"));
    std::uniform_real_distribution<float> mantissa(-4.f, 4.f);
    std::uniform_int_distribution<int> exponent(-100, 100);
    std::vector<float> values(size_t(w) * h * planes);
    for (float &v : values) v = std::ldexp(mantissa(rng), exponent(rng));
    values[3] = 0.f;  // not -0: the kernel's sum starts at +0, and +0 + -0 is +0
    vk::Buffer src(Ctx(), values.size() * sizeof(float), "src"),
        scratch(Ctx(), values.size() * sizeof(float), "scratch"),
        dst(Ctx(), values.size() * sizeof(float), "dst"), one(Ctx(), sizeof(float), "one");
    src.UploadFloats(values);
    one.UploadFloats({1.f});
    vk::Recorder recorder(Ctx());
    RecordRhfDownsample(Ctx(), recorder, src, w, h, planes, 1, one, 0, scratch, dst);
    recorder.Submit();
    std::vector<float> out = dst.DownloadFloats(values.size());
    EXPECT_EQ(std::memcmp(out.data(), values.data(), values.size() * sizeof(float)), 0);
}

// Texel bindings are read-only: binding a buffer there for writing is refused, by name.
TEST_F(VkTexelRecorder, WritingThroughATexelBindingThrows) {
    static const std::vector<uint32_t> code = BuiltSpirv("rhf/downsample.spv");
    ASSERT_FALSE(code.empty()) << "downsample.spv not found in the build tree";
    vk::KernelDesc desc{"rhf_downsample",
                        code.data(),
                        code.size() * sizeof(uint32_t),
                        RHF_DOWNSAMPLE_BINDINGS,
                        sizeof(shader::RhfDownsamplePush),
                        {},
                        1u << RHF_DOWNSAMPLE_SRC};
    const vk::Kernel &kernel = Ctx().GetKernel(desc);
    EXPECT_TRUE(kernel.IsTexel(RHF_DOWNSAMPLE_SRC));
    EXPECT_FALSE(kernel.IsTexel(RHF_DOWNSAMPLE_DST));
    vk::Buffer a(Ctx(), 64, "a"), b(Ctx(), 64, "b"), c(Ctx(), 64, "c");
    shader::RhfDownsamplePush push{4, 4, 4, 4, 1, 0, 0};
    vk::Recorder recorder(Ctx());
    EXPECT_TRUE(ThrowsError(ErrorKind::Internal, [&] {
        recorder.Dispatch(kernel, "bad",
                          {{RHF_DOWNSAMPLE_SRC, &a, vk::Access::Write},
                           {RHF_DOWNSAMPLE_DST, &b, vk::Access::Write},
                           {RHF_DOWNSAMPLE_WEIGHTS, &c, vk::Access::Read}},
                          push, 1);
    }));
    // The texel and storage kinds of one shader are different cache entries.
    vk::KernelDesc storage = desc;
    storage.texelBindings = 0;
    EXPECT_NE(vk::KernelKey(desc), vk::KernelKey(storage));
    // So are float and vec4 texels.
    vk::KernelDesc vec4 = desc;
    vec4.vec4Bindings = 1u << RHF_DOWNSAMPLE_SRC;
    EXPECT_NE(vk::KernelKey(desc), vk::KernelKey(vec4));
    EXPECT_FALSE(kernel.IsVec4(RHF_DOWNSAMPLE_SRC));
}

// A vec4 view covers a buffer whose size is not a whole number of texels (the allocation
// is rounded up to one), and the ledger still counts the bytes asked for.
TEST_F(VkTexelRecorder, Vec4ViewsCoverPartialTexels) {
    size_t before = Ctx().Ledger().live;
    vk::Buffer odd(Ctx(), 12, "odd");
    EXPECT_EQ(Ctx().Ledger().live, before + 12);
    EXPECT_NE(odd.Vec4View(), VK_NULL_HANDLE);
    EXPECT_EQ(odd.Vec4View(), odd.Vec4View());  // made once
    EXPECT_NE(odd.Vec4View(), odd.FloatView());
}

}  // namespace
}  // namespace mcd::test

namespace mcd::test {
namespace {

class VkLedger : public GpuTest {};

// The memory ledger sees every Buffer: live and peak bytes, allocations by name since the
// last reset, and releases, including through moves.
TEST_F(VkLedger, CountsAllocationsAndReleases) {
    vk::Context &ctx = Ctx();
    VkDeviceSize before = ctx.Ledger().live;
    ctx.ResetLedger();
    {
        vk::Buffer a(ctx, 1000, "ledger.a");
        vk::Buffer b(ctx, 0, "ledger.b");  // kept as one word
        EXPECT_EQ(ctx.Ledger().live, before + 1004);
        vk::Buffer c = std::move(a);
        EXPECT_EQ(ctx.Ledger().live, before + 1004);
    }
    EXPECT_EQ(ctx.Ledger().live, before);
    EXPECT_EQ(ctx.Ledger().peak, before + 1004);
    ASSERT_EQ(ctx.Ledger().allocations.size(), 2u);
    EXPECT_EQ(ctx.Ledger().allocations[0].first, "ledger.a");
    EXPECT_EQ(ctx.Ledger().allocations[0].second, 1000u);
    ctx.ResetLedger();
    EXPECT_TRUE(ctx.Ledger().allocations.empty());
    EXPECT_EQ(ctx.Ledger().peak, before);
}

// Pipelines built on the build threads (ContextOptions::pipelineThreads) while the recorder
// goes on, and bound when it submits: the same kernels, counts and bits as building each
// one when it is asked for. Two analyses of each basis in one submission ask for 12
// variants (bases x axes x parts).
TEST(VkBuildThreads, SameKernelsAndBitsAsBuildingEachWhenAsked) {
    const int w = 300, h = 70, channels = 3;
    Image in(w, h, channels);
    std::mt19937 rng(SeedFromName("build threads"));
    std::uniform_real_distribution<float> unit(-1, 1);
    for (float &v : in.data) v = unit(rng);
    auto run = [&](int threads, std::vector<std::string> *keys, int *built) {
        vk::Context context(vk::ContextOptions{.pipelineThreads = threads});
        vk::GpuImage src(context, w, h, channels, "src");
        src.Upload(in);
        vk::Recorder recorder(context);
        std::vector<std::unique_ptr<vk::GpuImage>> images;
        std::vector<Image> out;
        for (WaveletBasis basis :
             {WaveletBasis::Haar, WaveletBasis::Cdf97, WaveletBasis::LeGall53}) {
            images.push_back(std::make_unique<vk::GpuImage>(context, w, h, channels, "tmp"));
            vk::GpuImage &tmp = *images.back();
            images.push_back(std::make_unique<vk::GpuImage>(context, w, h, channels, "dst"));
            RecordWaveletAnalyze(context, recorder, basis, w, h, channels, src.View(),
                                 tmp.MutableView(), images.back()->MutableView(), "analyze");
        }
        recorder.Submit();
        for (size_t i = 1; i < images.size(); i += 2) out.push_back(images[i]->Download());
        *keys = context.KernelKeys();
        *built = context.Pipelines().built;
        return out;
    };
    std::vector<std::string> keysOne, keysMany;
    int builtOne = 0, builtMany = 0;
    std::vector<Image> one = run(1, &keysOne, &builtOne), many = run(4, &keysMany, &builtMany);
    EXPECT_GE(builtOne, 6);
    EXPECT_EQ(builtOne, int(keysOne.size()));
    EXPECT_EQ(builtMany, builtOne);
    ASSERT_EQ(keysOne.size(), keysMany.size());
    for (size_t i = 0; i < keysOne.size(); ++i)  // keys name the code by its address
        EXPECT_EQ(keysOne[i], keysMany[i]);
    ASSERT_EQ(one.size(), many.size());
    for (size_t i = 0; i < one.size(); ++i)
        EXPECT_EQ(0, std::memcmp(one[i].data.data(), many[i].data.data(),
                                 one[i].data.size() * sizeof(float)))
            << i;
}

// The build threads' pool: every task runs, Wait returns once all have finished, and a
// task's exception reaches whoever waits on its future.
TEST(VkBuildThreads, PoolRunsEveryTaskAndPassesErrorsOn) {
    for (int threads : {1, 3}) {
        vk::BuildPool pool(threads);
        std::atomic<int> done{0};
        std::vector<std::shared_future<void>> futures;
        for (int i = 0; i < 20; ++i) futures.push_back(pool.Run([&] { ++done; }));
        std::shared_future<void> failing =
            pool.Run([] { throw Error("build failed", ErrorKind::Device); });
        pool.Wait();
        EXPECT_EQ(done.load(), 20) << threads;
        for (auto &f : futures) EXPECT_NO_THROW(f.get());
        EXPECT_TRUE(ThrowsError(ErrorKind::Device, [&] { failing.get(); })) << threads;
    }
}

// The pipeline cache file (ContextOptions::pipelineCache): written when pipelines were
// built, read back by the next context, and a file from another device or a damaged one
// ignored, never an error. Whether the driver puts pipelines in it is its own affair
// (lavapipe writes the header only; README). Each build is waited for (Kernel::Pipeline):
// a kernel never bound is dropped unbuilt with its context, and nothing built writes nothing.
TEST(VkPipelineCache, WrittenReadBackAndForeignFilesIgnored) {
    const std::vector<uint32_t> *code = AnalyzeSpirv();
    ASSERT_NE(code, nullptr) << "analyze.spv not found next to the test binary's build tree";
    fs::path dir =
        fs::temp_directory_path() / ("mcd_pipeline_cache_" + std::to_string(getpid()));
    fs::remove_all(dir);
    std::string path = (dir / "sub" / "pipelines.bin").string();
    auto bytes = [&] {
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    VkPhysicalDeviceProperties props{};
    {
        vk::Context context(vk::ContextOptions{.pipelineCache = path});
        vkGetPhysicalDeviceProperties(context.PhysicalDevice(), &props);
        EXPECT_EQ(context.Pipelines().loadedBytes, 0u);
        context.GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar));
        EXPECT_EQ(context.Pipelines().built, 1);
        EXPECT_GT(context.Pipelines().seconds, 0);
    }
    std::string file = bytes();
    ASSERT_GE(file.size(), 16u + VK_UUID_SIZE) << "the cache file was not written";
    uint32_t header[4];
    std::memcpy(header, file.data(), sizeof header);
    EXPECT_EQ(header[1], uint32_t(VK_PIPELINE_CACHE_HEADER_VERSION_ONE));
    EXPECT_EQ(header[2], props.vendorID);
    EXPECT_EQ(header[3], props.deviceID);
    EXPECT_EQ(std::memcmp(file.data() + 16, props.pipelineCacheUUID, VK_UUID_SIZE), 0);
    {
        vk::Context context(vk::ContextOptions{.pipelineCache = path});
        EXPECT_EQ(context.Pipelines().loadedBytes, file.size());
        context.GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar)).Pipeline();
    }
    // Another device's cache (its device ID changed): read as none; left as it was by a
    // context that built nothing, replaced by this device's after a build.
    std::string foreign = file;
    foreign[12] ^= 1;
    std::ofstream(path, std::ios::binary | std::ios::trunc) << foreign;
    for (bool build : {false, true}) {
        {
            vk::Context context(vk::ContextOptions{.pipelineCache = path});
            EXPECT_EQ(context.Pipelines().loadedBytes, 0u);
            if (build) context.GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar)).Pipeline();
        }
        if (!build) {
            EXPECT_EQ(bytes(), foreign);
        }
    }
    EXPECT_EQ(bytes().substr(0, 16 + VK_UUID_SIZE), file.substr(0, 16 + VK_UUID_SIZE));
    // A file that is no pipeline cache (a frame given by mistake) is read as none and never
    // written over; no temporary file is left.
    std::ofstream(path, std::ios::binary | std::ios::trunc) << "not a pipeline cache";
    {
        vk::Context context(vk::ContextOptions{.pipelineCache = path});
        EXPECT_EQ(context.Pipelines().loadedBytes, 0u);
        context.GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar)).Pipeline();
    }
    EXPECT_EQ(bytes(), "not a pipeline cache");
    // Absent at the start, written during the run (an output given the cache's name): that
    // file stays as the run left it.
    fs::remove(path);
    {
        vk::Context context(vk::ContextOptions{.pipelineCache = path});
        context.GetKernel(AnalyzeDesc(*code, WaveletBasis::Haar)).Pipeline();
        std::ofstream(path, std::ios::binary | std::ios::trunc) << "an output";
    }
    EXPECT_EQ(bytes(), "an output");
    // A directory is no cache file: an error naming it, before any work.
    std::string directory = (dir / "sub" / "cache.dir").string();
    fs::create_directories(directory);
    try {
        vk::Context context(vk::ContextOptions{.pipelineCache = directory});
        ADD_FAILURE() << "a directory was taken for a pipeline cache";
    } catch (const Error &e) {
        EXPECT_EQ(e.Kind(), ErrorKind::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find(directory), std::string::npos) << e.what();
    }
    fs::remove(directory);
    int files = 0;
    for ([[maybe_unused]] const auto &e : fs::directory_iterator(dir / "sub")) ++files;
    EXPECT_EQ(files, 1);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace mcd::test
