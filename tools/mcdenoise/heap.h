// How the tool's process takes memory from glibc's allocator (the library leaves it alone).
#pragma once

#include <string>

namespace mcd::tool {

// The GLIBC_TUNABLES value that asks glibc's allocator for transparent huge pages
// (glibc.malloc.hugetlb=1) and to keep freed memory in its heap (glibc.malloc.mmap_max=0,
// glibc.malloc.trim_threshold above any heap), each appended to `current` (null: unset)
// unless `current` names it; empty when `current` names glibc.malloc.hugetlb, whatever its
// value (the user's choice stands, for all three).
std::string TunablesWithHugePages(const char *current);

// Back the allocator's large blocks (a large frame's planes, tiles' crops) with huge pages
// where the kernel gives them on request: the kernel then faults and zeroes a fresh block
// in 2 MiB pieces, not 4 KiB pages; and keep what the process frees for its next blocks,
// which the kernel would otherwise fault and zero again (for more peak memory: the heap
// keeps its fragments). glibc reads its tunables only at a process's start, so
// the process starts itself again once with the tunable added to its environment (which
// its own child processes inherit). Returns when nothing is to be done (not glibc on
// Linux, the tunable already set) or the restart failed; the run then goes on as it is.
void UseHugePages(char **argv);

}  // namespace mcd::tool
