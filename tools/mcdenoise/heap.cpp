#include "tools/mcdenoise/heap.h"

#include <cstdlib>

#if defined(__GLIBC__) && defined(__linux__)
#include <unistd.h>
#endif

namespace mcd::tool {

namespace {

constexpr const char *kHugePagesName = "glibc.malloc.hugetlb";

// Set across the restart to the caller's GLIBC_TUNABLES ("=" and its value, or empty when
// unset), so that the restarted process puts it back for its children and does not
// restart again.
constexpr const char *kCallersTunables = "MCD_CALLERS_GLIBC_TUNABLES";

// What the tool adds: huge pages, and freed memory kept in the heap for the next block (no
// large block mapped on its own, the heap's top never handed back), so that a block reused
// is not faulted and zeroed by the kernel again; each with the environment variable glibc
// also reads for it (a user's setting there stands too).
struct Setting {
    const char *tunable, *alias;
};
constexpr Setting kSettings[] = {
    {"glibc.malloc.hugetlb=1", nullptr},
    {"glibc.malloc.mmap_max=0", "MALLOC_MMAP_MAX_"},
    {"glibc.malloc.trim_threshold=68719476736", "MALLOC_TRIM_THRESHOLD_"}};

// Whether the tunables `value` (name=value pairs joined by ':') name `name`.
bool Names(const std::string &value, const std::string &name) {
    for (size_t start = 0; start <= value.size();) {
        size_t end = value.find(':', start);
        if (end == std::string::npos) end = value.size();
        const std::string pair = value.substr(start, end - start);
        if (pair.substr(0, pair.find('=')) == name) return true;
        start = end + 1;
    }
    return false;
}

}  // namespace

std::string TunablesWithHugePages(const char *current,
                                  const std::function<bool(const char *)> &aliasSet) {
    const std::string value = current ? current : "";
    // The user's own huge-page setting, whatever its value, stands for all of them.
    if (Names(value, kHugePagesName)) return "";
    std::string tunables = value;
    for (const Setting &setting : kSettings) {
        const std::string text = setting.tunable;
        if (Names(value, text.substr(0, text.find('='))) ||
            (setting.alias && aliasSet && aliasSet(setting.alias)))
            continue;
        tunables += (tunables.empty() ? "" : ":") + text;
    }
    return tunables;
}

void UseHugePages(char **argv) {
#if defined(__GLIBC__) && defined(__linux__)
    if (const char *callers = std::getenv(kCallersTunables)) {
        // Restarted: the caller's environment back, for the processes this one starts.
        if (callers[0] == '=')
            setenv("GLIBC_TUNABLES", callers + 1, 1);
        else
            unsetenv("GLIBC_TUNABLES");
        unsetenv(kCallersTunables);
        return;
    }
    const char *current = std::getenv("GLIBC_TUNABLES");
    const bool wasSet = current != nullptr;
    const std::string before = wasSet ? current : "";
    const std::string tunables = TunablesWithHugePages(
        current, [](const char *name) { return std::getenv(name) != nullptr; });
    if (tunables.empty() || setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
    setenv(kCallersTunables, wasSet ? ("=" + before).c_str() : "", 1);
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
    unsetenv(kCallersTunables);
#else
    (void)argv;
#endif
}

}  // namespace mcd::tool
