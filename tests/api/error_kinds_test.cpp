// Each mcd::ErrorKind reaches the C API as its MCDError code and the command line as its
// exit status, with the library's message unchanged; the statuses are distinct, and those
// the command line can reach are checked through the built tool.
#include <gtest/gtest.h>

#include <filesystem>
#include <new>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "harness/errors.h"
#include "harness/tool.h"
#include "host/api/c_api.h"
#include "host/image.h"
#include "host/io/frame.h"
#include "mcdenoise/mcdenoise_c.h"
#include "tools/mcdenoise/exit_status.h"

namespace mcd::test {
namespace {

// The table the C header and docs/usage.md promise, written out here rather than taken
// from the code under test.
struct KindCodes {
    ErrorKind kind;
    MCDError code;
    int exitStatus;
};
const std::vector<KindCodes> kKinds = {
    {ErrorKind::InvalidArgument, MCD_ERROR_INVALID_ARGUMENT, 1},
    {ErrorKind::MissingLayer, MCD_ERROR_MISSING_LAYER, 4},
    {ErrorKind::NonFiniteInput, MCD_ERROR_NON_FINITE_INPUT, 5},
    {ErrorKind::OutOfMemory, MCD_ERROR_OUT_OF_MEMORY, 6},
    {ErrorKind::Device, MCD_ERROR_DEVICE, 7},
    {ErrorKind::Io, MCD_ERROR_IO, 8},
    {ErrorKind::Internal, MCD_ERROR_INTERNAL, 3},
    {ErrorKind::Cancelled, MCD_ERROR_CANCELLED, 9},
};

// What a C API call gives for an exception thrown inside it.
std::pair<MCDError, std::string> CodeOf(const std::exception_ptr &error) {
    // Guarded gives its first argument, the call's failure value, when the body throws.
    bool ok = api::Guarded(false, [&]() -> bool { std::rethrow_exception(error); });
    EXPECT_FALSE(ok);
    const char *message = nullptr;
    MCDError code = mcdGetError(&message);
    return {code, message ? message : "(null)"};
}

TEST(ErrorKinds, EachKindReachesItsCodeAndExitStatus) {
    std::set<int> statuses;
    for (const KindCodes &k : kKinds) {
        SCOPED_TRACE(ErrorKindName(k.kind));
        std::string text = std::string("something ") + ErrorKindName(k.kind) + " happened";
        std::exception_ptr error = std::make_exception_ptr(Error(text, k.kind));
        auto [code, message] = CodeOf(error);
        EXPECT_EQ(code, k.code);
        EXPECT_EQ(message, text);
        EXPECT_STREQ(mcdErrorName(code), ErrorKindName(k.kind));
        tool::Failure failure = tool::DescribeFailure(error);
        EXPECT_EQ(int(failure.status), k.exitStatus);
        EXPECT_EQ(failure.message, text);
        EXPECT_EQ(tool::KindOf(error), k.kind);
        statuses.insert(k.exitStatus);
    }
    // One status per kind, none of them success or a usage error.
    EXPECT_EQ(statuses.size(), kKinds.size());
    EXPECT_FALSE(statuses.count(0));
    EXPECT_FALSE(statuses.count(int(tool::ExitStatus::Usage)));
    EXPECT_EQ(int(tool::ExitStatus::Usage), 2);
}

// Exceptions that are not mcd::Error: memory, the file system, and anything else (a bug).
TEST(ErrorKinds, OtherExceptionsHaveAKindToo) {
    std::exception_ptr memory = std::make_exception_ptr(std::bad_alloc());
    EXPECT_EQ(CodeOf(memory).first, MCD_ERROR_OUT_OF_MEMORY);
    EXPECT_EQ(int(tool::DescribeFailure(memory).status), 6);
    EXPECT_EQ(tool::DescribeFailure(memory).message, "out of memory");

    std::exception_ptr files = std::make_exception_ptr(std::filesystem::filesystem_error(
        "cannot list", "some/dir", std::make_error_code(std::errc::permission_denied)));
    EXPECT_EQ(tool::KindOf(files), ErrorKind::Io);
    EXPECT_EQ(int(tool::DescribeFailure(files).status), 8);

    std::exception_ptr bug = std::make_exception_ptr(std::logic_error("an invariant broke"));
    EXPECT_EQ(CodeOf(bug).first, MCD_ERROR_INTERNAL);
    tool::Failure failure = tool::DescribeFailure(bug);
    EXPECT_EQ(int(failure.status), 3);
    EXPECT_EQ(failure.message, "internal error: an invariant broke");
}

// Through the built tool: one failure of each kind the command line can meet (a cancel
// needs a library caller), each with its status and the library's message.
class ErrorKindsCli : public ::testing::Test {
  protected:
    ToolResult Run(const std::string &args, const std::string &env = "") {
        return tool.Run(args, env);
    }
    ::testing::AssertionResult Exits(const ToolResult &r, ErrorKind kind) {
        int expected = 0;
        for (const KindCodes &k : kKinds)
            if (k.kind == kind) expected = k.exitStatus;
        if (r.code == expected && r.err.rfind("mcdenoise: error: ", 0) == 0)
            return ::testing::AssertionSuccess();
        return ::testing::AssertionFailure()
               << "exit code " << r.code << ", expected " << expected << " ("
               << ErrorKindName(kind) << "):\n"
               << r.All();
    }
    ToolDir tool{"mcd_error_kinds"};
};

TEST_F(ErrorKindsCli, EachReachableKindExitsWithItsStatus) {
    Image color(6, 5, 3, 0.5f), nan = color;
    nan.At(1, 2, 3) = std::numeric_limits<float>::quiet_NaN();
    io::WriteExr(tool.Path("plain.exr").string(), {{"color", &color}});
    io::WriteExr(tool.Path("nan.exr").string(), {{"color", &nan}});

    EXPECT_TRUE(
        Exits(Run("denoise plain.exr --frames 1 -o o.exr"), ErrorKind::InvalidArgument));
    EXPECT_TRUE(Exits(Run("denoise plain.exr --method rhf -o o.exr"), ErrorKind::MissingLayer));
    // The guide --demodulate names, missing: the layer named and how to get it, not the list
    // of the layers read.
    ToolResult guide = Run("denoise plain.exr --method bayes --demodulate albedo -o o.exr");
    EXPECT_TRUE(Exits(guide, ErrorKind::MissingLayer));
    EXPECT_NE(
        guide.err.find("--demodulate albedo needs a layer the frame lacks: no albedo layer"),
        std::string::npos)
        << guide.err;
    // A layer of the wrong shape is the frame's fault, said with the file and the layer.
    Image albedo2(6, 5, 2, 0.5f);
    io::WriteExr(tool.Path("albedo2.exr").string(), {{"color", &color}, {"albedo", &albedo2}});
    ToolResult shape = Run("denoise albedo2.exr --method pivot -o o.exr");
    EXPECT_TRUE(Exits(shape, ErrorKind::InvalidArgument));
    EXPECT_NE(shape.err.find("albedo2.exr: layer 'albedo' is 6x5x2"), std::string::npos)
        << shape.err;
    EXPECT_TRUE(
        Exits(Run("denoise nan.exr --method bayes -o o.exr"), ErrorKind::NonFiniteInput));
    ToolResult reference = Run("denoise plain.exr --method bayes --reference nan.exr -o o.exr");
    EXPECT_TRUE(Exits(reference, ErrorKind::NonFiniteInput));
    EXPECT_NE(reference.err.find("--reference nan.exr: 1 NaN/Inf value, the first at pixel (3, "
                                 "2), channel 1"),
              std::string::npos)
        << reference.err;
    // A band of records (and its radius above and below) beyond one buffer binding.
    EXPECT_TRUE(Exits(Run("bench tracing --sizes 32768x8 --spp 64 --radii 1000 --cpu-size 0"),
                      ErrorKind::OutOfMemory));
    EXPECT_TRUE(Exits(Run("denoise absent.exr -o o.exr"), ErrorKind::Io));
    // No Vulkan driver at all: the loader finds no device.
    EXPECT_TRUE(
        Exits(Run("wavelet builtin:rings@8x8 --levels 1",
                  "VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json "),
              ErrorKind::Device));
    // diff's own check failing is the library's bug: no float32 stage meets 0 exactly.
    ASSERT_EQ(Run("render --size 13x9 --spp 2 -o r.exr").code, 0);
    EXPECT_TRUE(Exits(Run("diff r.exr --method awr --max-nmse 0"), ErrorKind::Internal));
    EXPECT_FALSE(std::filesystem::exists(tool.Path("o.exr")));
}

}  // namespace
}  // namespace mcd::test
