#include "tools/mcdenoise/heap.h"

#include <cstdlib>

#if defined(__GLIBC__) && defined(__linux__)
#include <unistd.h>
#endif

namespace mcd::tool {

namespace {

constexpr const char *kHugePagesName = "glibc.malloc.hugetlb";

}  // namespace

std::string TunablesWithHugePages(const char *current) {
    const std::string setting = std::string(kHugePagesName) + "=1";
    if (!current || !*current) return setting;
    // Tunables are name=value pairs joined by ':'.
    const std::string value = current;
    for (size_t start = 0; start <= value.size();) {
        size_t end = value.find(':', start);
        if (end == std::string::npos) end = value.size();
        const std::string pair = value.substr(start, end - start);
        if (pair.compare(0, pair.find('='), kHugePagesName) == 0) return "";
        start = end + 1;
    }
    return value + ":" + setting;
}

void UseHugePages(char **argv) {
#if defined(__GLIBC__) && defined(__linux__)
    const char *current = std::getenv("GLIBC_TUNABLES");
    const bool wasSet = current != nullptr;
    const std::string before = wasSet ? current : "";
    const std::string tunables = TunablesWithHugePages(current);
    if (tunables.empty() || setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
    // By the binary's own path, not /proc/self/exe: the process keeps its name.
    char path[4096];
    const ssize_t length = readlink("/proc/self/exe", path, sizeof path - 1);
    if (length > 0) {
        path[length] = '\0';
        execv(path, argv);
    }
    // The restart failed: go on without huge pages, the environment as it was.
    if (wasSet)
        setenv("GLIBC_TUNABLES", before.c_str(), 1);
    else
        unsetenv("GLIBC_TUNABLES");
#else
    (void)argv;
#endif
}

}  // namespace mcd::tool
