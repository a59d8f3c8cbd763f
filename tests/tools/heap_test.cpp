// The tool's request for huge pages (heap.h): the GLIBC_TUNABLES value it restarts with,
// and a restarted process that runs once and succeeds.
#include "tools/mcdenoise/heap.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

TEST(CliHeap, TunablesGainHugePagesOnce) {
    using mcd::tool::TunablesWithHugePages;
    const std::string added =
        "glibc.malloc.hugetlb=1:glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold="
        "68719476736";
    EXPECT_EQ(TunablesWithHugePages(nullptr), added);
    EXPECT_EQ(TunablesWithHugePages(""), added);
    EXPECT_EQ(TunablesWithHugePages("glibc.malloc.arena_max=2"),
              "glibc.malloc.arena_max=2:" + added);
    // Already named, whatever its value: the user's choice stands, no restart.
    EXPECT_EQ(TunablesWithHugePages("glibc.malloc.hugetlb=1"), "");
    EXPECT_EQ(TunablesWithHugePages("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=0"), "");
    // A user's own heap setting is kept, the others added.
    EXPECT_EQ(TunablesWithHugePages("glibc.malloc.mmap_max=4"),
              "glibc.malloc.mmap_max=4:glibc.malloc.hugetlb=1:"
              "glibc.malloc.trim_threshold=68719476736");
    // A heap setting made through glibc's own environment variable stands too.
    auto aliasSet = [](const char *name) { return std::string(name) == "MALLOC_MMAP_MAX_"; };
    EXPECT_EQ(TunablesWithHugePages(nullptr, aliasSet),
              "glibc.malloc.hugetlb=1:glibc.malloc.trim_threshold=68719476736");
    // A longer name that starts with it is another tunable.
    EXPECT_EQ(TunablesWithHugePages("glibc.malloc.hugetlbx=1"),
              "glibc.malloc.hugetlbx=1:" + added);
}

// The restarted process (the marker set) puts the caller's GLIBC_TUNABLES back, or unsets
// it, and drops the marker, for the processes it starts (`bench` runs peers and Blender);
// it does not restart again.
TEST(CliHeap, RestartedProcessPutsTheCallersTunablesBack) {
    char name[] = "heap_test";
    char *argv[] = {name, nullptr};
    setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1", 1);
    setenv("MCD_CALLERS_GLIBC_TUNABLES", "=glibc.malloc.arena_max=4", 1);
    mcd::tool::UseHugePages(argv);
    ASSERT_NE(std::getenv("GLIBC_TUNABLES"), nullptr);
    EXPECT_EQ(std::string(std::getenv("GLIBC_TUNABLES")), "glibc.malloc.arena_max=4");
    EXPECT_EQ(std::getenv("MCD_CALLERS_GLIBC_TUNABLES"), nullptr);
    setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1", 1);
    setenv("MCD_CALLERS_GLIBC_TUNABLES", "", 1);
    mcd::tool::UseHugePages(argv);
    EXPECT_EQ(std::getenv("GLIBC_TUNABLES"), nullptr);
    EXPECT_EQ(std::getenv("MCD_CALLERS_GLIBC_TUNABLES"), nullptr);
}

// The tool restarted with the tunables prints its version once and succeeds, whether or not
// the caller's environment names other tunables.
TEST(CliHeap, RestartedToolRunsOnce) {
    for (const std::string env :
         {"env -u GLIBC_TUNABLES", "env GLIBC_TUNABLES=glibc.malloc.arena_max=4"}) {
        const std::string command = env + " " + MCD_TOOL_PATH + " --version";
        FILE *pipe = popen(command.c_str(), "r");
        ASSERT_NE(pipe, nullptr);
        std::string out;
        char buffer[256];
        while (fgets(buffer, sizeof buffer, pipe)) out += buffer;
        EXPECT_EQ(pclose(pipe), 0) << command;
        EXPECT_EQ(out, "mcdenoise 0.1.0\n") << command;
    }
}

}  // namespace
