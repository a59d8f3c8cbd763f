// Subcommands of the mcdenoise tool. Each Add*Command declares the command's options in a
// struct of its own and a callback that calls one Run* function with them; a failure is an
// exception, which main() reports (exit_status.h).
#pragma once

#include <CLI/CLI.hpp>

#include <initializer_list>
#include <map>
#include <string>

#include "host/api/device.h"
#include "host/image.h"
#include "host/vk/context.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::tool {

// The help's heading over the device's options (a command's own stay under "Options").
inline constexpr const char *kDeviceGroup = "Device";

// Options every GPU subcommand takes.
struct DeviceOptions {
    std::string device, pipelineCache;
    bool validation = false;
    void Add(CLI::App *command);
    vk::ContextOptions ContextOptions() const { return {device, validation, pipelineCache}; }
    mcd::DeviceOptions Options() const { return {device, validation, pipelineCache}; }
};

void AddInfoCommand(CLI::App &app);
void AddWaveletCommand(CLI::App &app);
void AddBenchCommand(CLI::App &app);
void AddBenchQualityCommand(CLI::App *bench);  // the `bench quality` subcommand
void AddBenchTracingCommand(CLI::App *bench);  // the `bench tracing` subcommand
void AddBenchReadCommand(CLI::App *bench);     // the `bench read` subcommand
void AddBenchFlickerCommand(CLI::App *bench);  // the `bench flicker` subcommand
void AddBenchRealCommand(CLI::App *bench);     // the `bench real` subcommand
void AddBenchAutoCommand(CLI::App *bench);     // the `bench auto` subcommand
void AddBenchKernelsCommand(CLI::App *bench);  // the `bench kernels` subcommand
void AddRenderCommand(CLI::App &app);
void AddCompareCommand(CLI::App &app);
void AddDenoiseCommand(CLI::App &app);
void AddDiffCommand(CLI::App &app);
void AddAccumulateCommand(CLI::App &app);

// Largest image side the tool accepts for sizes it makes up itself.
constexpr int kMaxImageSide = 32768;

// Parse "WxH" (e.g. 2048x2048), the whole string; throws mcd::Error.
void ParseSize(const std::string &text, int *width, int *height);

// Refuse, before any work, an output that is a directory, whose extension is not listed,
// whose directory does not exist or is not writable, or that exists and is not writable.
// `role` names it in the message ("output", "--preview").
void CheckOutputPath(const std::string &path, std::initializer_list<const char *> extensions,
                     const std::string &role = "output");

// Refuse an input that is a directory, saying so (the image readers would say they know no
// such format). `role` names it ("input", "--reference").
void CheckInputFile(const std::string &path, const std::string &role = "input");

// Write one image as a tonemapped PNG if `path` ends in .png, else as a float EXR (layer
// color) with `metadata`; with `alpha` (the input's), as RGBA.
void WriteImage(const std::string &path, const Image &image,
                const std::map<std::string, std::string> &metadata = {},
                const Image *alpha = nullptr);

// Create `path` as a directory (with parents) or throw if it cannot be one.
void PrepareDirectory(const std::string &path);

// Refuse, before any work and creating nothing, a directory PrepareDirectory could not
// make: `path` is a file, or the nearest existing directory above it is not writable.
// `role` names it in the message ("--dump").
void CheckDirectory(const std::string &path, const std::string &role);

}  // namespace mcd::tool
