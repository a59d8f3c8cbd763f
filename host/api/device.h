// What the public mcd::Device keeps to itself: the Vulkan context underneath, for the
// library, the project's tools and its tests (never in an installed header).
#pragma once

#include <memory>

#include "host/vk/context.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd {

struct Device::Impl {
    std::unique_ptr<vk::Context> owned;
    vk::Context *context = nullptr;
};

struct DeviceAccess {
    static vk::Context &Context(Device &device) { return *device.impl->context; }
    static Device Borrow(vk::Context &context) {
        auto impl = std::make_unique<Device::Impl>();
        impl->context = &context;
        return Device(std::move(impl));
    }
};

namespace api {

// The Vulkan context under `device`.
inline vk::Context &ContextOf(Device &device) {
    return DeviceAccess::Context(device);
}

// A device over a context someone else owns (the tests' shared one, a tool's own).
inline Device BorrowDevice(vk::Context &context) {
    return DeviceAccess::Borrow(context);
}

}  // namespace api
}  // namespace mcd
