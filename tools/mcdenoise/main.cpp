// mcdenoise: a denoiser for Monte Carlo renders on Vulkan compute.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>

#include "host/error.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {

void DeviceOptions::Add(CLI::App *command) {
    command->add_option("--device", device,
                        "Vulkan device: index or name substring (default: $MCD_DEVICE, else "
                        "the first discrete GPU, then integrated, then CPU)");
    command->add_flag("--validation", validation,
                      "enable the Khronos validation layer and print its messages");
    command->add_option("--pipeline-cache", pipelineCache,
                        "file for the Vulkan driver's pipeline cache: read at the start, "
                        "written at the end, so the next run builds its pipelines faster where "
                        "the driver keeps them (lavapipe does not; README)");
}

void ParseSize(const std::string &text, int *width, int *height) {
    int w = 0, h = 0, used = 0;
    char x = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%n", &w, &x, &h, &used) != 3 ||
        used != int(text.size()) || (x != 'x' && x != 'X') || w <= 0 || h <= 0)
        throw Error("size '" + text + "' is not WIDTHxHEIGHT with positive numbers");
    if (w > kMaxImageSide || h > kMaxImageSide)
        throw Error(
            fmt::format("size '{}' is larger than {} pixels on a side", text, kMaxImageSide));
    *width = w;
    *height = h;
}

void CheckOutputPath(const std::string &path, std::initializer_list<const char *> extensions) {
    namespace fs = std::filesystem;
    std::string ext = fs::path(path).extension().string();
    bool known = false;
    std::string list;
    for (const char *e : extensions) {
        known |= ext == e;
        list += std::string(list.empty() ? "" : ", ") + e;
    }
    if (!known)
        throw Error(
            fmt::format("output '{}': unsupported extension '{}' (use {})", path, ext, list));
    fs::path dir = fs::path(path).parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw Error(
            fmt::format("output '{}': directory '{}' does not exist", path, dir.string()));
}

void WriteImage(const std::string &path, const Image &image,
                const std::map<std::string, std::string> &metadata, const Image *alpha) {
    if (std::filesystem::path(path).extension() == ".png")
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
                                ec ? ec.message() : "it is a file"));
}

}  // namespace mcd::tool

int main(int argc, char **argv) {
    CLI::App app{"mcdenoise: denoise Monte Carlo renders with GLSL compute kernels on Vulkan"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "mcdenoise 0.1.0");
    mcd::tool::AddInfoCommand(app);
    mcd::tool::AddRenderCommand(app);
    mcd::tool::AddAccumulateCommand(app);
    mcd::tool::AddDenoiseCommand(app);
    mcd::tool::AddCompareCommand(app);
    mcd::tool::AddWaveletCommand(app);
    mcd::tool::AddBenchCommand(app);
    mcd::tool::AddDiffCommand(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError &e) {
        return app.exit(e);
    } catch (const mcd::Error &e) {
        std::fprintf(stderr, "mcdenoise: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc &) {
        std::fprintf(stderr, "mcdenoise: error: out of memory\n");
        return 1;
    } catch (const std::filesystem::filesystem_error &e) {
        std::fprintf(stderr, "mcdenoise: error: %s\n", e.what());
        return 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "mcdenoise: internal error: %s\n", e.what());
        return 3;
    }
    return 0;
}
