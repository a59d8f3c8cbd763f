// `mcdenoise bench tracing`: GPU time of the tracing filter's gather (Ershov section 5) on
// synthetic records, in bands of rows as a renderer hands them, and the CPU reference's
// time beside it. Figures are printed, never asserted.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cpu_reference/tracing_filter.h"
#include "host/error.h"
#include "host/kernels/tracing_gather.h"
#include "host/tracing.h"
#include "host/vk/context.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

// A counter-based generator: pixel (x, y)'s numbers do not depend on the band it is made in.
struct PixelRandom {
    uint64_t state;
    PixelRandom(int x, int y) : state(uint64_t(uint32_t(x)) << 32 | uint32_t(y)) {}
    double Next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return double((z ^ (z >> 31)) >> 11) * 0x1p-53;
    }
};

// Records of frame rows [y0, y0 + rows): a relief (normals tilting with x and y) with a
// textured Lambert and a glossy lobe; samples are cosine-weighted about the normal under a
// sky with a sun, a tenth of them without a record (a mirror event).
TracingRecords SyntheticRecords(int width, int y0, int rows, int spp) {
    TracingRecords r;
    r.width = width;
    r.y0 = y0;
    r.rows = rows;
    r.spp = spp;
    r.surfaces.resize(size_t(width) * rows);
    r.samples.resize(r.surfaces.size() * spp);
    for (int y = y0; y < y0 + rows; ++y)
        for (int x = 0; x < width; ++x) {
            PixelRandom rng(x, y);
            size_t i = size_t(y - y0) * width + x;
            TracingSurface &s = r.surfaces[i];
            double ax = 0.5 * std::sin(0.05 * x + 0.02 * y), ay = 0.4 * std::cos(0.03 * y);
            double len = std::sqrt(ax * ax + ay * ay + 1);
            double n[3] = {ax / len, ay / len, 1 / len};
            bool check = ((x / 16) + (y / 16)) % 2 == 0;
            for (int c = 0; c < 3; ++c) {
                s.position[c] = c == 0 ? float(x) : c == 1 ? float(y) : 0.f;
                s.normal[c] = float(n[c]);
                s.wo[c] = c == 2 ? 1.f : 0.f;
                s.diffuse[c] = float(check ? 0.7 : 0.2 + 0.1 * c);
                s.glossy[c] = 0.2f;
            }
            s.kappa = 10;
            s.valid = (x + 3 * y) % 97 == 0 ? 0.f : 1.f;
            // Tangents for cosine-weighted directions about n.
            double t[3] = {n[2], 0, -n[0]}, tl = std::sqrt(t[0] * t[0] + t[2] * t[2]);
            t[0] /= tl, t[2] /= tl;
            double b[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2],
                           n[0] * t[1] - n[1] * t[0]};
            for (int j = 0; j < spp; ++j) {
                TracingSample &sample = r.samples[i * spp + j];
                double pick = rng.Next(), cosT = std::sqrt(rng.Next()),
                       phi = 2 * kPi * rng.Next();
                if (pick < 0.1) {
                    sample = TracingSample{};
                    continue;
                }
                double sinT = std::sqrt(1 - cosT * cosT), u[3];
                for (int c = 0; c < 3; ++c)
                    u[c] = cosT * n[c] + sinT * (std::cos(phi) * t[c] + std::sin(phi) * b[c]);
                double pdf = 0.9 * cosT / kPi, fcos[3];
                ref::TracingBsdfCos(s, u, fcos);
                double sun = 10 * std::exp(20 * (0.6 * u[0] + 0.8 * u[2] - 1));
                for (int c = 0; c < 3; ++c) {
                    double light = 0.4 + 0.3 * u[2] + sun;
                    sample.direction[c] = float(u[c]);
                    sample.radiance[c] = float(light);
                    sample.own[c] = float(fcos[c] * light / pdf);
                }
                sample.pdf = float(pdf);
            }
        }
    return r;
}

// A comma-separated list of integers >= 0; an error names the option and the item.
std::vector<int> ParseList(const std::string &text, const char *option) {
    std::vector<int> values;
    std::stringstream stream(text);
    std::string item;
    while (std::getline(stream, item, ',')) {
        if (item.empty()) continue;
        size_t used = 0;
        int value = -1;
        try {
            value = std::stoi(item, &used);
        } catch (const std::exception &) {
        }
        if (value < 0 || used != item.size())
            throw Error(fmt::format("{}: '{}' is not an integer >= 0", option, item),
                        ErrorKind::InvalidArgument);
        values.push_back(value);
    }
    return values;
}

struct TracingBenchOptions {
    std::string sizes = "256x256,1024x1024", radii = "8,30", cpuSize = "256x256";
    std::string cpuRadii = "8";
    int spp = 16, bandRows = 256, maxOutRows = 0;
    DeviceOptions device;
};

void RunBenchTracing(const TracingBenchOptions &opt) {
    vk::Context context(opt.device.ContextOptions());
    TracingGather gather(context);
    std::vector<int> radii = ParseList(opt.radii, "--radii"),
                     cpuRadii = ParseList(opt.cpuRadii, "--cpu-radii");
    fmt::print(
        "bench tracing: gather of eqs. 14-17 on synthetic records, {} spp, bands of "
        "up to {} output rows, on {}\n",
        opt.spp, opt.bandRows, context.Info().name);
    std::stringstream sizes(opt.sizes);
    std::string size;
    while (std::getline(sizes, size, ',')) {
        int width = 0, height = 0;
        ParseSize(size, &width, &height);
        int timedRows = opt.maxOutRows > 0 ? std::min(opt.maxOutRows, height) : height;
        for (int radius : radii) {
            TracingParams params;
            params.radius = radius;
            int fit = gather.MaxRecordRows(width, opt.spp) - 2 * radius;
            int band = std::min(opt.bandRows, fit);
            if (band < 1)
                throw Error(fmt::format("bench tracing: a {}-wide band at {} spp and radius {} "
                                        "does not fit one binding",
                                        width, opt.spp, radius),
                            ErrorKind::OutOfMemory);
            // The rows of the middle of the frame when only some are timed.
            int first = (height - timedRows) / 2;
            double gpuMs = 0, wallMs = 0;
            int bands = 0;
            for (int y = first; y < first + timedRows; y += band) {
                int rows = std::min(band, first + timedRows - y);
                int r0 = std::max(0, y - radius), r1 = std::min(height, y + rows + radius);
                TracingRecords records = SyntheticRecords(width, r0, r1 - r0, opt.spp);
                Clock::time_point start = Clock::now();
                gather.Run(records, params, y, rows);
                wallMs +=
                    std::chrono::duration<double, std::milli>(Clock::now() - start).count();
                gpuMs += std::max(0.0, gather.LastGpuMs());
                ++bands;
            }
            fmt::print(
                "  {}x{} radius {:>2}: GPU {:10.1f} ms, wall with uploads {:10.1f} ms, "
                "{} band(s){}\n",
                width, height, radius, gpuMs, wallMs, bands,
                timedRows < height ? fmt::format(" ({} of {} rows timed)", timedRows, height)
                                   : std::string());
            std::fflush(stdout);
        }
    }
    if (!opt.cpuSize.empty() && opt.cpuSize != "0") {
        int width = 0, height = 0;
        ParseSize(opt.cpuSize, &width, &height);
        TracingRecords records = SyntheticRecords(width, 0, height, opt.spp);
        for (int radius : cpuRadii) {
            TracingParams params;
            params.radius = radius;
            Clock::time_point start = Clock::now();
            ref::TracingFilter(records, params, 0, height);
            double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
            fmt::print("  CPU reference (1 thread, double) {}x{} radius {:>2}: {:10.1f} ms\n",
                       width, height, radius, ms);
            std::fflush(stdout);
        }
    }
}

}  // namespace

void AddBenchTracingCommand(CLI::App *bench) {
    auto opt = std::make_shared<TracingBenchOptions>();
    CLI::App *tracing = bench->add_subcommand(
        "tracing",
        "Time the tracing filter's gather (Ershov section 5) on synthetic records\n\n"
        "Per size and radius, and the CPU reference's time beside it.");
    tracing->add_option("--sizes", opt->sizes, "frame sizes WxH, comma-separated")
        ->capture_default_str();
    tracing->add_option("--radii", opt->radii, "filter radii, comma-separated")
        ->capture_default_str();
    CheckRange(
        tracing->add_option("--spp", opt->spp, "samples per pixel")->capture_default_str(), 1,
        1 << 16, true);
    CheckRange(
        tracing->add_option("--band-rows", opt->bandRows, "output rows per band (per Run)")
            ->capture_default_str(),
        1, 1 << 20, true);
    tracing
        ->add_option("--max-rows", opt->maxOutRows,
                     "time only this many output rows from the middle of each frame (0: all)")
        ->capture_default_str();
    tracing->add_option("--cpu-size", opt->cpuSize, "frame size of the CPU reference (0: skip)")
        ->capture_default_str();
    tracing->add_option("--cpu-radii", opt->cpuRadii, "radii of the CPU reference")
        ->capture_default_str();
    opt->device.Add(tracing);
    tracing->callback([opt] { RunBenchTracing(*opt); });
}

}  // namespace mcd::tool
