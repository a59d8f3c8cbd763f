// mcdenoise: a denoiser for Monte Carlo renders on Vulkan compute.
#include <cstdio>
#include <exception>

#include "host/error.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {

void DeviceOptions::Add(CLI::App *command) {
    command->add_option("--device", device,
                        "Vulkan device: index or name substring (default: $MCD_DEVICE, else "
                        "the first discrete GPU, then integrated, then CPU)");
    command->add_flag("--validation", validation,
                      "enable the Khronos validation layer and print its messages");
}

void ParseSize(const std::string &text, int *width, int *height) {
    int w = 0, h = 0;
    char x = 0;
    if (std::sscanf(text.c_str(), "%d%c%d", &w, &x, &h) != 3 || (x != 'x' && x != 'X') ||
        w <= 0 || h <= 0)
        throw Error("size '" + text + "' is not WIDTHxHEIGHT with positive numbers");
    *width = w;
    *height = h;
}

}  // namespace mcd::tool

int main(int argc, char **argv) {
    CLI::App app{"mcdenoise: denoise Monte Carlo renders with GLSL compute kernels on Vulkan"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "mcdenoise 0.1.0");
    mcd::tool::AddInfoCommand(app);
    mcd::tool::AddWaveletCommand(app);
    mcd::tool::AddBenchCommand(app);
    mcd::tool::AddPlannedCommands(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError &e) {
        return app.exit(e);
    } catch (const mcd::Error &e) {
        std::fprintf(stderr, "mcdenoise: error: %s\n", e.what());
        return 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "mcdenoise: internal error: %s\n", e.what());
        return 3;
    }
    return 0;
}
