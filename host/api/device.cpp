// mcd::Device: a Vulkan context, owned or borrowed.
#include "host/api/device.h"

namespace mcd {

Device::Device(const DeviceOptions &options) : impl(std::make_unique<Impl>()) {
    impl->owned = std::make_unique<vk::Context>(
        vk::ContextOptions{options.device, options.validation, options.pipelineCache});
    impl->context = impl->owned.get();
}

Device::~Device() = default;
Device::Device(Device &&) noexcept = default;
Device &Device::operator=(Device &&) noexcept = default;

Device::Device(std::unique_ptr<Impl> impl) : impl(std::move(impl)) {}

std::string Device::Name() const {
    return impl->context->Info().name;
}

std::vector<std::string> Device::TakeValidationMessages() {
    return impl->context->TakeValidationMessages();
}

}  // namespace mcd
