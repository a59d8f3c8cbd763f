// `mcdenoise info`: Vulkan devices and their limits, or the layers of a frame.
#include <fmt/format.h>

#include <cmath>

#include "host/io/frame.h"
#include "host/io/image_file.h"
#include "tools/mcdenoise/commands.h"

namespace mcd::tool {
namespace {

void PrintDevices(const std::string &selected) {
    std::vector<vk::DeviceInfo> devices = vk::ListDevices();
    if (devices.empty()) {
        fmt::print("no Vulkan devices found\n");
        return;
    }
    vk::Context context({selected, false});
    for (const vk::DeviceInfo &d : devices) {
        bool chosen = d.index == context.Info().index;
        fmt::print("{} {}: {} ({}), Vulkan {}.{}.{}{}\n", chosen ? "*" : " ", d.index, d.name,
                   vk::DeviceTypeName(d.type), VK_API_VERSION_MAJOR(d.apiVersion),
                   VK_API_VERSION_MINOR(d.apiVersion), VK_API_VERSION_PATCH(d.apiVersion),
                   d.hasCompute ? "" : ", no compute queue");
        const VkPhysicalDeviceLimits &l = d.limits;
        fmt::print("    device-local memory       {:.1f} GiB\n",
                   double(d.deviceLocalBytes) / (1u << 30));
        fmt::print("    maxStorageBufferRange     {} bytes ({} MiB)\n", l.maxStorageBufferRange,
                   l.maxStorageBufferRange >> 20);
        fmt::print("    maxComputeWorkGroupCount  {} x {} x {}\n",
                   l.maxComputeWorkGroupCount[0], l.maxComputeWorkGroupCount[1],
                   l.maxComputeWorkGroupCount[2]);
        fmt::print("    maxComputeWorkGroupSize   {} x {} x {} ({} invocations)\n",
                   l.maxComputeWorkGroupSize[0], l.maxComputeWorkGroupSize[1],
                   l.maxComputeWorkGroupSize[2], l.maxComputeWorkGroupInvocations);
        fmt::print("    maxComputeSharedMemory    {} bytes\n", l.maxComputeSharedMemorySize);
        fmt::print("    maxPushConstantsSize      {} bytes\n", l.maxPushConstantsSize);
        fmt::print("    timestamps                {}{}\n", d.timestamps ? "yes" : "no",
                   d.timestamps ? fmt::format(" ({} ns per tick)", l.timestampPeriod) : "");
        fmt::print("    push descriptors          {}\n", d.pushDescriptors ? "yes" : "no");
    }
    fmt::print("(* = the device mcdenoise uses with these settings)\n");
}

// Every part of a multi-part EXR: its name, size and channels, which one is read, which
// are joined to it, and what is not read and why.
void PrintParts(const std::string &path) {
    if (!io::IsExrFile(path)) return;
    io::ImageHeader header = io::ReadExrHeader(path);
    for (size_t k = 0; k < header.partList.size(); ++k) {
        const io::ImageHeader::Part &part = header.partList[k];
        std::string channels;
        for (const std::string &name : part.channelNames)
            channels += (channels.empty() ? "" : ",") + name;
        fmt::print("  part {}{}: {}x{}, {} channel{} ({}){}{}\n", k,
                   part.name.empty() ? "" : fmt::format(" '{}'", part.name), part.width,
                   part.height, part.channelNames.size(),
                   part.channelNames.size() == 1 ? "" : "s", channels,
                   int(k) == header.part
                       ? (part.color ? "  <- read: it holds the colour" : "  <- read")
                   : part.joined ? "  <- joined"
                                 : "",
                   part.left.empty() ? "" : fmt::format(" (not read: {})", part.left));
    }
}

void PrintFrame(const std::string &path) {
    CheckInputFile(path, "frame");
    io::Frame frame = io::ReadFrame(path);
    fmt::print("{}: {}x{}\n", path, frame.width, frame.height);
    PrintParts(path);
    if (auto data = frame.metadata.find(io::kDataWindowKey); data != frame.metadata.end())
        fmt::print("  data window {}, display window {} (xmin ymin xmax ymax)\n", data->second,
                   frame.metadata[io::kDisplayWindowKey]);
    for (const auto &[name, image] : frame.layers) {
        double sum = 0;
        size_t nonFinite = 0;
        for (float v : image.data) {
            if (std::isfinite(v))
                sum += v;
            else
                ++nonFinite;
        }
        size_t finite = image.Size() - nonFinite;
        fmt::print("  {:<12} {:>3} channel{}  mean {:.6g} (of finite values){}\n", name,
                   image.channels, image.channels == 1 ? " " : "s", finite ? sum / finite : 0.0,
                   nonFinite ? fmt::format("  ({} non-finite values)", nonFinite) : "");
    }
    for (const auto &[key, value] : frame.metadata)
        if (key.rfind("mcd:", 0) == 0) fmt::print("  {} = {}\n", key, value);
}

struct InfoOptions {
    std::vector<std::string> frames;
    std::string device;
};

void RunInfo(const InfoOptions &opt) {
    if (opt.frames.empty()) PrintDevices(opt.device);
    for (const std::string &path : opt.frames) PrintFrame(path);
}

}  // namespace

void AddInfoCommand(CLI::App &app) {
    auto opt = std::make_shared<InfoOptions>();
    CLI::App *info = app.add_subcommand(
        "info", "List Vulkan devices and their limits, or the layers of a frame file");
    info->add_option("frames", opt->frames, "frame files (EXR, PFM, HDR, PNG) to describe");
    info->add_option("--device", opt->device, "device to mark as selected (index or name)");
    info->callback([opt] { RunInfo(*opt); });
}

}  // namespace mcd::tool
