#include "host/vk/dispatch_count.h"

#include <mutex>

namespace mcd::vk {
namespace {

std::mutex countMutex;
std::map<std::string, uint64_t> counts;
bool keeping = false;
std::vector<KeptDispatch> kept;

}  // namespace

void CountDispatch(const std::string &kernel) {
    std::lock_guard<std::mutex> lock(countMutex);
    ++counts[kernel];
}

std::map<std::string, uint64_t> DispatchCounts() {
    std::lock_guard<std::mutex> lock(countMutex);
    return counts;
}

void KeepDispatches(bool on) {
    std::lock_guard<std::mutex> lock(countMutex);
    keeping = on;
    if (on) kept.clear();
}

bool KeepingDispatches() {
    std::lock_guard<std::mutex> lock(countMutex);
    return keeping;
}

void KeepDispatch(KeptDispatch dispatch) {
    std::lock_guard<std::mutex> lock(countMutex);
    if (keeping) kept.push_back(std::move(dispatch));
}

std::vector<KeptDispatch> KeptDispatches() {
    std::lock_guard<std::mutex> lock(countMutex);
    return kept;
}

}  // namespace mcd::vk
