// VkResult checking: every call goes through MCD_VK, which throws an mcd::Error naming the
// call, the result, the file and the line.
#pragma once

#include <volk.h>

#include <string>

#include "host/error.h"

namespace mcd::vk {

const char *ResultName(VkResult result);
[[noreturn]] void ThrowVkError(VkResult result, const char *call, const char *file, int line);

}  // namespace mcd::vk

#define MCD_VK(call)                                                          \
    do {                                                                      \
        VkResult mcdVkResult_ = (call);                                       \
        if (mcdVkResult_ != VK_SUCCESS)                                       \
            ::mcd::vk::ThrowVkError(mcdVkResult_, #call, __FILE__, __LINE__); \
    } while (0)
