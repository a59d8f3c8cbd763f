// `mcdenoise bench read`: how long reading a frame takes, all layers and the layers a method
// reads, and the pixels alone with our EXR decoder beside OpenEXR's.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <memory>

#include "host/error.h"
#include "host/io/exr_read.h"
#include "host/io/frame.h"
#include "host/io/image_file.h"
#include "host/io/layer_names.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {
namespace {

using Clock = std::chrono::steady_clock;

// The median of `repeat` runs of work: "wall ms (CPU ms)", the CPU time of every thread
// of the process (on a shared machine the steadier figure).
template <typename Work>
std::string MedianMs(int repeat, Work work) {
    std::vector<std::pair<double, double>> ms;
    for (int r = 0; r < repeat; ++r) {
        Clock::time_point start = Clock::now();
        std::clock_t cpuStart = std::clock();
        work();
        ms.push_back({std::chrono::duration<double, std::milli>(Clock::now() - start).count(),
                      1000.0 * double(std::clock() - cpuStart) / CLOCKS_PER_SEC});
    }
    std::sort(ms.begin(), ms.end());
    return fmt::format("{:7.0f} ms ({:5.0f} CPU)", ms[ms.size() / 2].first,
                       ms[ms.size() / 2].second);
}

struct ReadBenchOptions {
    std::vector<std::string> inputs;
    std::string method = "awr";
    int repeats = 3;
};

void RunBenchRead(const ReadBenchOptions &opt) {
    Method method(opt.method);
    ReadOptions subset{method.Uses()};
    std::string names;
    for (const std::string &layer : subset.layers) names += (names.empty() ? "" : ",") + layer;
    fmt::print("bench read: median of {} reads; {} reads {}\n", opt.repeats, opt.method,
               names.empty() ? "every layer" : names);
    for (const std::string &path : opt.inputs) {
        std::error_code ec;
        double megabytes = double(std::filesystem::file_size(path, ec)) * 1e-6;
        Frame probe = ReadFrame(path);
        fmt::print("{}: {}x{}, {} layers, {:.1f} MB\n", path, probe.width, probe.height,
                   probe.layers.size(), megabytes);
        probe = {};
        std::string all = MedianMs(opt.repeats, [&] { ReadFrame(path); });
        std::string some = MedianMs(opt.repeats, [&] { ReadFrame(path, subset); });
        fmt::print("  ReadFrame, every layer      {}\n", all);
        fmt::print("  ReadFrame, {:<16} {}\n", opt.method + "'s layers", some);

        // The pixels alone, every channel and the method's, with each decoder.
        if (!io::IsExrFile(path)) continue;
        const io::ImageHeader spec = io::ReadExrHeader(path);
        std::vector<io::LayerChannels> layers = io::GroupChannels(spec.channelNames);
        auto wanted = [&](const std::string &layer) {
            return subset.layers.empty() ||
                   std::find(subset.layers.begin(), subset.layers.end(), layer) !=
                       subset.layers.end();
        };
        for (bool few : {false, true}) {
            std::vector<std::vector<float>> planes;
            std::vector<io::ExrTarget> targets;
            for (const io::LayerChannels &layer : layers)
                if (!few || wanted(layer.name))
                    for (int c : layer.channels) {
                        planes.emplace_back(size_t(spec.width) * spec.height);
                        targets.push_back({spec.channelNames[c], planes.back().data()});
                    }
            std::string ms[2];
            for (io::ExrDecoder decoder : {io::ExrDecoder::Auto, io::ExrDecoder::OpenExr})
                ms[decoder == io::ExrDecoder::OpenExr] = MedianMs(opt.repeats, [&] {
                    io::ReadExrFrameChannels(path, spec, targets, decoder);
                });
            fmt::print("  pixels, {:2} of {} channels: {}; OpenEXR's reader {}\n",
                       targets.size(), spec.channelNames.size(), ms[0], ms[1]);
        }
    }
}

}  // namespace

void AddBenchReadCommand(CLI::App *bench) {
    auto opt = std::make_shared<ReadBenchOptions>();
    CLI::App *read = bench->add_subcommand(
        "read",
        "Time reading frames: every layer, a method's layers, the EXR pixels alone\n\n"
        "The pixels alone are read with our decoder and with OpenEXR's.");
    read->add_option("inputs", opt->inputs, "frames to read")
        ->required()
        ->check(CLI::ExistingFile);
    read->add_option("--method", opt->method, "the method whose layers are read")
        ->capture_default_str();
    CheckRange(read->add_option("--repeat", opt->repeats, "timed reads of each kind")
                   ->capture_default_str(),
               1, 100, true);
    read->callback([opt] { RunBenchRead(*opt); });
}

}  // namespace mcd::tool
