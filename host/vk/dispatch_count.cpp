#include "host/vk/dispatch_count.h"

#include <mutex>

namespace mcd::vk {
namespace {

std::mutex countMutex;
std::map<std::string, uint64_t> counts;

}  // namespace

void CountDispatch(const std::string &kernel) {
    std::lock_guard<std::mutex> lock(countMutex);
    ++counts[kernel];
}

std::map<std::string, uint64_t> DispatchCounts() {
    std::lock_guard<std::mutex> lock(countMutex);
    return counts;
}

}  // namespace mcd::vk
