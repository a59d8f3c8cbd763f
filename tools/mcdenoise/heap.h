// How the tool's process takes memory from glibc's allocator (the library leaves it alone).
#pragma once

#include <functional>
#include <string>

namespace mcd::tool {

// The GLIBC_TUNABLES value that asks glibc's allocator for transparent huge pages
// (glibc.malloc.hugetlb=1) and to keep freed memory in its heap (glibc.malloc.mmap_max=0,
// glibc.malloc.trim_threshold above any heap), each appended to `current` (null: unset)
// unless `current` names it; empty when `current` names glibc.malloc.hugetlb, whatever its
// value (the user's choice stands, for all three). A heap setting whose own environment
// variable is set (aliasSet(MALLOC_MMAP_MAX_ or MALLOC_TRIM_THRESHOLD_)) is not added.
std::string TunablesWithHugePages(const char *current,
                                  const std::function<bool(const char *)> &aliasSet = {});

// Back the allocator's large blocks (a large frame's planes, tiles' crops) with huge pages
// where the kernel gives them on request: the kernel then faults and zeroes a fresh block
// in 2 MiB pieces, not 4 KiB pages; and keep what the process frees for its next blocks,
// which the kernel would otherwise fault and zero again (for more peak memory: the heap
// keeps its fragments). glibc reads its tunables only at a process's start, so the
// process starts itself again once with the tunables added to its environment; the
// restarted process puts the caller's GLIBC_TUNABLES back for the processes it starts
// (the bench's peers, Blender). Returns when nothing is to be done (not glibc on Linux,
// the tunable already set), after the restart, or when the restart failed; the run then
// goes on as it is.
void UseHugePages(char **argv);

}  // namespace mcd::tool
