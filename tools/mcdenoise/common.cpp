// The helpers every command shares (commands.h).
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <unistd.h>

#include "host/api/front_end.h"
#include "host/error.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/path_guard.h"

namespace mcd::tool {

void DeviceOptions::Add(CLI::App *command) {
    command
        ->add_option("--device", device,
                     "Vulkan device: index or name substring (default: $MCD_DEVICE, else the "
                     "first discrete GPU, then integrated, then CPU)")
        ->group(kDeviceGroup);
    command
        ->add_flag("--validation", validation,
                   "enable the Khronos validation layer and print its messages")
        ->group(kDeviceGroup);
    command
        ->add_option("--pipeline-cache", pipelineCache,
                     "file for the Vulkan driver's pipeline cache: read at the start, written "
                     "at the end, so the next run builds its pipelines faster where the driver "
                     "keeps them (lavapipe does not; README)")
        ->group(kDeviceGroup);
}

void ParseSize(const std::string &text, int *width, int *height) {
    int w = 0, h = 0, used = 0;
    char x = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%n", &w, &x, &h, &used) != 3 ||
        used != int(text.size()) || (x != 'x' && x != 'X') || w <= 0 || h <= 0)
        throw Error("size '" + text + "' is not WIDTHxHEIGHT with positive numbers",
                    ErrorKind::InvalidArgument);
    if (w > kMaxImageSide || h > kMaxImageSide)
        throw Error(
            fmt::format("size '{}' is larger than {} pixels on a side", text, kMaxImageSide),
            ErrorKind::InvalidArgument);
    *width = w;
    *height = h;
}

void CheckOutputPath(const std::string &path, std::initializer_list<const char *> extensions,
                     const std::string &role) {
    namespace fs = std::filesystem;
    const std::string list =
        api::OrList({extensions.begin(), extensions.end()});  // ".exr or .png"
    std::error_code ec;
    if (!path.empty() && (path.back() == '/' || fs::is_directory(path, ec)))
        throw Error(fmt::format("{} '{}' is a directory; give a file name ending in {}", role,
                                path, list),
                    ErrorKind::InvalidArgument);
    std::string ext = LowerExtension(path);
    bool known = false;
    for (const char *e : extensions) known |= ext == e;
    if (ext.empty())
        throw Error(fmt::format("{} '{}' has no extension; give a file name ending in {}", role,
                                path, list),
                    ErrorKind::InvalidArgument);
    if (!known)
        throw Error(fmt::format("{} '{}': unsupported extension '{}' (use {})", role, path,
                                fs::path(path).extension().string(), list),
                    ErrorKind::InvalidArgument);
    fs::path dir = fs::path(path).parent_path();
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw Error(
            fmt::format("{} '{}': directory '{}' does not exist", role, path, dir.string()),
            ErrorKind::Io);
    // The write goes to a new file beside the target (through a link, the file it leads
    // to), renamed over it: that directory must take one, and a file the user made
    // read-only stays so.
    if (fs::is_symlink(path, ec)) dir = fs::weakly_canonical(path, ec).parent_path();
    const std::string where = dir.empty() ? "." : dir.string();
    if (::access(where.c_str(), W_OK | X_OK) != 0)
        throw Error(fmt::format("{} '{}': directory '{}' is not writable: {}", role, path,
                                where, std::strerror(errno)),
                    ErrorKind::Io);
    if (::access(path.c_str(), F_OK) == 0 && ::access(path.c_str(), W_OK) != 0)
        throw Error(fmt::format("{} '{}' exists and is not writable: {}", role, path,
                                std::strerror(errno)),
                    ErrorKind::Io);
}

void CheckInputFile(const std::string &path, const std::string &role) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(fmt::format("{} '{}' is a directory; give an image file (EXR, PFM, HDR or "
                                "PNG)",
                                role, path),
                    ErrorKind::InvalidArgument);
}

void WriteImage(const std::string &path, const Image &image,
                const std::map<std::string, std::string> &metadata, const Image *alpha) {
    if (LowerExtension(path) == ".png")
        io::WritePngWithAlpha(path, image, alpha);
    else if (alpha)
        io::WriteExr(path, {{"color", &image}, {"alpha", alpha}}, metadata);
    else
        io::WriteExr(path, {{"color", &image}}, metadata);
}

void PrepareDirectory(const std::string &path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(path, ec);
    if (ec || !fs::is_directory(path))
        throw Error(fmt::format("cannot use '{}' as a directory: {}", path,
                                ec ? ec.message() : "it is a file"),
                    ErrorKind::Io);
}

void CheckDirectory(const std::string &path, const std::string &role) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path dir = fs::absolute(path, ec);
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw Error(fmt::format("{} '{}' is a file, not a directory", role, path),
                    ErrorKind::Io);
    // The nearest existing directory takes the new ones.
    while (!fs::exists(dir, ec) && dir.has_parent_path() && dir.parent_path() != dir)
        dir = dir.parent_path();
    if (!fs::is_directory(dir, ec))
        throw Error(
            fmt::format("{} '{}': '{}' is a file, not a directory", role, path, dir.string()),
            ErrorKind::Io);
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw Error(fmt::format("{} '{}': directory '{}' is not writable: {}", role, path,
                                dir.string(), std::strerror(errno)),
                    ErrorKind::Io);
}

}  // namespace mcd::tool
