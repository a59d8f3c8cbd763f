// How the tool's process takes memory from glibc's allocator (the library leaves it alone).
#pragma once

#include <string>

namespace mcd::tool {

// The GLIBC_TUNABLES value that asks glibc's allocator for transparent huge pages
// (glibc.malloc.hugetlb=1), appended to `current` (null: unset); empty when `current`
// already names that tunable, whatever its value (the user's choice stands).
std::string TunablesWithHugePages(const char *current);

// Back the allocator's large blocks (a large frame's planes, tiles' crops) with huge pages
// where the kernel gives them on request: the kernel then faults and zeroes a fresh block
// in 2 MiB pieces, not 4 KiB pages. glibc reads its tunables only at a process's start, so
// the process starts itself again once with the tunable added to its environment (which
// its own child processes inherit). Returns when nothing is to be done (not glibc on
// Linux, the tunable already set) or the restart failed; the run then goes on as it is.
void UseHugePages(char **argv);

}  // namespace mcd::tool
