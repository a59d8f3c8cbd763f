// Subcommands of the mcdenoise tool. Each Add*Command registers its options and callback
// on the app; callbacks throw mcd::Error on failure, which main() reports.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

#include "host/vk/context.h"

namespace mcd::tool {

// Options every GPU subcommand takes.
struct DeviceOptions {
    std::string device;
    bool validation = false;
    void Add(CLI::App *command);
    vk::ContextOptions ContextOptions() const { return {device, validation}; }
};

void AddInfoCommand(CLI::App &app);
void AddWaveletCommand(CLI::App &app);
void AddBenchCommand(CLI::App &app);
void AddPlannedCommands(CLI::App &app);

// Parse "WxH" (e.g. 2048x2048); throws mcd::Error.
void ParseSize(const std::string &text, int *width, int *height);

}  // namespace mcd::tool
