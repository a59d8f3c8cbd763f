// One Vulkan context per test process, with the Khronos validation layer on. Any
// validation message during a test fails it.
#pragma once

#include <gtest/gtest.h>

#include "host/image.h"
#include "host/vk/context.h"
#include "host/vk/gpu_image.h"

namespace mcd::test {

// The shared context (created on first use; device from $MCD_DEVICE or the best one).
vk::Context &TestContext();

class GpuTest : public ::testing::Test {
  protected:
    void SetUp() override;
    void TearDown() override;
    vk::Context &Ctx() { return TestContext(); }
};

// A GPU image of `image`'s shape holding its values.
vk::GpuImage UploadImage(vk::Context &ctx, const Image &image, const char *name);

template <typename Param>
class GpuTestWithParam : public GpuTest, public ::testing::WithParamInterface<Param> {};

}  // namespace mcd::test
