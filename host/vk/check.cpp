#include "host/vk/check.h"

#include <fmt/format.h>

namespace mcd::vk {

const char *ResultName(VkResult result) {
    switch (result) {
#define MCD_CASE(r) \
    case r:         \
        return #r;
        MCD_CASE(VK_SUCCESS)
        MCD_CASE(VK_NOT_READY)
        MCD_CASE(VK_TIMEOUT)
        MCD_CASE(VK_INCOMPLETE)
        MCD_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        MCD_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        MCD_CASE(VK_ERROR_INITIALIZATION_FAILED)
        MCD_CASE(VK_ERROR_DEVICE_LOST)
        MCD_CASE(VK_ERROR_MEMORY_MAP_FAILED)
        MCD_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        MCD_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        MCD_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        MCD_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        MCD_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        MCD_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
        MCD_CASE(VK_ERROR_FRAGMENTED_POOL)
        MCD_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
        MCD_CASE(VK_ERROR_INVALID_SHADER_NV)
        MCD_CASE(VK_ERROR_UNKNOWN)
        MCD_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        MCD_CASE(VK_ERROR_FRAGMENTATION)
        MCD_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        MCD_CASE(VK_PIPELINE_COMPILE_REQUIRED)
#undef MCD_CASE
        default:
            return "VK_ERROR_(unknown)";
    }
}

void ThrowVkError(VkResult result, const char *call, const char *file, int line) {
    bool memory =
        result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY;
    throw Error(fmt::format("Vulkan call failed with {} ({}): {} at {}:{}", ResultName(result),
                            int(result), call, file, line),
                memory ? ErrorKind::OutOfMemory : ErrorKind::Device);
}

}  // namespace mcd::vk
