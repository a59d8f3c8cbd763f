#include "harness/gpu_fixture.h"

#include <cstdio>
#include <memory>

namespace mcd::test {

vk::Context &TestContext() {
    static std::unique_ptr<vk::Context> context = [] {
        auto c = std::make_unique<vk::Context>(vk::ContextOptions{.validation = true});
        std::fprintf(stderr, "[mcd] test device: %s (validation %s)\n", c->Info().name.c_str(),
                     c->ValidationEnabled() ? "on" : "off");
        return c;
    }();
    return *context;
}

vk::GpuImage UploadImage(vk::Context &ctx, const Image &image, const char *name) {
    vk::GpuImage gpu(ctx, image.width, image.height, image.channels, name);
    gpu.Upload(image);
    return gpu;
}

void GpuTest::SetUp() {
    TestContext().TakeValidationMessages();
}

void GpuTest::TearDown() {
    for (const std::string &message : TestContext().TakeValidationMessages())
        ADD_FAILURE() << message;
}

}  // namespace mcd::test
