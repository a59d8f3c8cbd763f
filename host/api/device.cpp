// mcd::Device: a Vulkan context, owned or borrowed.
#include "host/vk/context.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd {

struct Device::Impl {
    std::unique_ptr<vk::Context> owned;
    vk::Context *context = nullptr;
};

Device::Device(const DeviceOptions &options) : impl(std::make_unique<Impl>()) {
    impl->owned = std::make_unique<vk::Context>(
        vk::ContextOptions{options.device, options.validation, options.pipelineCache});
    impl->context = impl->owned.get();
}

Device::~Device() = default;
Device::Device(Device &&) noexcept = default;
Device &Device::operator=(Device &&) noexcept = default;

Device::Device(std::unique_ptr<Impl> impl) : impl(std::move(impl)) {}

Device Device::Borrow(vk::Context &context) {
    auto impl = std::make_unique<Impl>();
    impl->context = &context;
    return Device(std::move(impl));
}

std::string Device::Name() const {
    return impl->context->Info().name;
}

std::vector<std::string> Device::TakeValidationMessages() {
    return impl->context->TakeValidationMessages();
}

vk::Context &Device::Context() {
    return *impl->context;
}

}  // namespace mcd
