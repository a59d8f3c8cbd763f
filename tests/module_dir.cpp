// The OpenImageIO module for the test binaries and the tools they start: the one of the
// build tree the test binary sits in (<build>/tests/<test> -> <build>/libmcdenoise_oiio.so),
// so that a build tree copied elsewhere (the GPU bundle) uses its own; else the path the
// build recorded. Linked into each test binary itself, not through the harness library, so
// that it is set before main whichever tests run; a value already in the environment wins.
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;

[[maybe_unused]] const bool kModuleDirSet = [] {
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    fs::path build = exe.parent_path().parent_path();
    std::string dir = !ec && fs::is_regular_file(build / "libmcdenoise_oiio.so", ec)
                          ? build.string()
                          : std::string(MCD_OIIO_MODULE_BUILD_DIR);
    return setenv("MCD_OIIO_MODULE_DIR", dir.c_str(), 0) == 0;
}();

}  // namespace
