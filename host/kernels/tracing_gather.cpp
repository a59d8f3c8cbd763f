#include "host/kernels/tracing_gather.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "host/error.h"
#include "host/vk/buffer.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "host/vk/recorder.h"
#include "tracing/gather.h"
#include "tracing/gather_spv.h"

namespace mcd {
namespace {

// The per-sample buffers: slot, name and fields (direction xyz, pdf, radiance rgb, own rgb).
constexpr int kSampleBuffers = 4;
constexpr uint32_t kSampleSlots[kSampleBuffers] = {TRACING_GATHER_DIRECTION, TRACING_GATHER_PDF,
                                                   TRACING_GATHER_RADIANCE, TRACING_GATHER_OWN};
constexpr const char *kSampleNames[kSampleBuffers] = {"tracing.direction", "tracing.pdf",
                                                      "tracing.radiance", "tracing.own"};
constexpr int kSampleFields[kSampleBuffers] = {3, 1, 3, 3};
// A band is split into dispatches of about this many weight evaluations (seconds on
// lavapipe, milliseconds on a discrete GPU), so that none runs long enough for a driver's
// watchdog, but of at least kMinGroups workgroups, so that a device is kept busy.
constexpr double kWorkPerDispatch = 2e9;
constexpr int64_t kMinGroups = 256;

}  // namespace

struct TracingGather::Buffers {
    vk::Buffer surfaces, out;
    std::array<vk::Buffer, kSampleBuffers> samples;
};

TracingGather::TracingGather(vk::Context &context)
    : context(context), buffers(std::make_unique<Buffers>()) {}

TracingGather::~TracingGather() = default;

int TracingGather::MaxRecordRows(int width, int spp) const {
    if (width <= 0 || spp <= 0) return 0;
    double floats = double(context.BindingBytes()) / sizeof(float);
    double rows = std::min(floats / (3.0 * spp * width),
                           floats / (double(TRACING_SURFACE_PLANES) * width));
    return int(std::min(rows, 1e9));
}

std::vector<float> TracingGather::Run(const TracingRecords &records,
                                      const TracingParams &params, int outY0, int outRows) {
    const int width = records.width, rows = records.rows, spp = records.spp;
    if (width <= 0 || rows <= 0 || spp <= 0)
        throw Error(
            fmt::format("tracing gather: records of {}x{} pixels at {} spp", width, rows, spp),
            ErrorKind::Internal);
    int maxRows = MaxRecordRows(width, spp);
    if (rows > maxRows)
        throw Error(fmt::format("tracing gather: a band of {} rows x {} pixels at {} spp needs "
                                "{:.1f} MiB for its "
                                "sample directions, over this device's {:.1f} MiB per binding: "
                                "at most {} rows of "
                                "records fit (output rows plus 2 x radius)",
                                rows, width, spp, 3.0 * spp * width * rows * 4 / (1 << 20),
                                double(context.BindingBytes()) / (1 << 20), maxRows),
                    ErrorKind::OutOfMemory);

    size_t pixels = size_t(width) * rows;
    if (records.surfaces.size() != pixels || records.samples.size() != pixels * spp)
        throw Error(
            fmt::format("tracing gather: {} surfaces and {} samples for {}x{} pixels at {} spp",
                        records.surfaces.size(), records.samples.size(), width, rows, spp),
            ErrorKind::Internal);
    if (outRows <= 0 || outY0 < records.y0 || outY0 + outRows > records.y0 + rows)
        throw Error(fmt::format("tracing gather: output rows {}..{} are not inside the "
                                "records' rows {}..{}",
                                outY0, outY0 + outRows - 1, records.y0, records.y0 + rows - 1),
                    ErrorKind::Internal);
    auto finiteNonNegative = [](float v) { return std::isfinite(v) && v >= 0; };
    if (params.radius < 0 || !finiteNonNegative(params.alpha) ||
        !finiteNonNegative(params.beta) || !finiteNonNegative(params.gamma) ||
        !finiteNonNegative(params.selfFloor) || params.selfFloor > 1)
        throw Error(fmt::format("tracing gather: parameters radius {} alpha {} beta {} gamma "
                                "{} selfFloor {}; radius, alpha, beta, gamma must be finite "
                                "and >= 0, selfFloor in [0, 1]",
                                params.radius, params.alpha, params.beta, params.gamma,
                                params.selfFloor),
                    ErrorKind::InvalidArgument);
    // Planar upload: a field's values of adjacent pixels adjacent.
    std::vector<float> plane(std::max(pixels * TRACING_SURFACE_PLANES, pixels * spp * 3));
    for (size_t i = 0; i < pixels; ++i) {
        const TracingSurface &s = records.surfaces[i];
        for (int c = 0; c < 3; ++c) {
            plane[(TRACING_SURF_NORMAL + c) * pixels + i] = s.normal[c];
            plane[(TRACING_SURF_WO + c) * pixels + i] = s.wo[c];
            plane[(TRACING_SURF_DIFFUSE + c) * pixels + i] = s.diffuse[c];
            plane[(TRACING_SURF_GLOSSY + c) * pixels + i] = s.glossy[c];
        }
        plane[TRACING_SURF_KAPPA * pixels + i] = s.kappa;
        plane[TRACING_SURF_VALID * pixels + i] = s.valid;
    }
    auto ensure = [&](vk::Buffer &buffer, size_t bytes, const char *name) {
        if (buffer.Bytes() < bytes) buffer = vk::Buffer(context, bytes, name);
    };
    size_t outPixels = size_t(width) * outRows;
    ensure(buffers->surfaces, pixels * TRACING_SURFACE_PLANES * 4, "tracing.surfaces");
    ensure(buffers->out, outPixels * 3 * 4, "tracing.out");
    buffers->surfaces.Upload(plane.data(), pixels * TRACING_SURFACE_PLANES * 4);
    for (int k = 0; k < kSampleBuffers; ++k) {
        size_t fieldSize = pixels * spp;
        for (int f = 0; f < kSampleFields[k]; ++f)
            for (size_t i = 0; i < pixels; ++i)
                for (int s = 0; s < spp; ++s) {
                    const TracingSample &t = records.samples[i * spp + s];
                    float v = k == 0   ? t.direction[f]
                              : k == 1 ? t.pdf
                              : k == 2 ? t.radiance[f]
                                       : t.own[f];
                    plane[f * fieldSize + size_t(s) * pixels + i] = v;
                }
        size_t bytes = fieldSize * kSampleFields[k] * sizeof(float);
        ensure(buffers->samples[k], bytes, kSampleNames[k]);
        buffers->samples[k].Upload(plane.data(), bytes);
    }

    uint32_t texel = 1u << TRACING_GATHER_SURFACES;
    for (uint32_t slot : kSampleSlots) texel |= 1u << slot;
    const vk::Kernel &kernel = context.GetKernel({"tracing_gather",
                                                  k_tracing_gather_spv,
                                                  sizeof(k_tracing_gather_spv),
                                                  TRACING_GATHER_BINDINGS,
                                                  sizeof(shader::TracingGatherPush),
                                                  {},
                                                  texel});
    std::vector<vk::Binding> bindings = {
        {TRACING_GATHER_SURFACES, &buffers->surfaces, vk::Access::Read},
        {TRACING_GATHER_OUT, &buffers->out, vk::Access::Write}};
    for (int k = 0; k < kSampleBuffers; ++k)
        bindings.push_back({kSampleSlots[k], &buffers->samples[k], vk::Access::Read});

    // A disk past the band's diagonal holds the same neighbours (and keeps radius^2 an int).
    const int radius = std::min(params.radius, width + rows);
    // Weight evaluations per pixel: the disk's area times the own and the lent samples.
    double work = (3.14159 * radius * radius + 1) * (2.0 * spp + 1);
    int64_t groups =
        std::clamp<int64_t>(int64_t(kWorkPerDispatch / work / TRACING_LOCAL_SIZE), kMinGroups,
                            context.Limits().maxComputeWorkGroupCount[0]);
    int64_t chunk = groups * TRACING_LOCAL_SIZE;
    vk::Recorder recorder(context);
    for (int64_t base = 0; base < int64_t(outPixels); base += chunk) {
        int count = int(std::min<int64_t>(chunk, int64_t(outPixels) - base));
        shader::TracingGatherPush push{
            width,     rows,  spp,          radius,      outY0 - records.y0, outRows,
            int(base), count, params.alpha, params.beta, params.gamma,       params.selfFloor};
        recorder.Dispatch(kernel, "tracing.gather", bindings, push,
                          uint32_t((count + TRACING_LOCAL_SIZE - 1) / TRACING_LOCAL_SIZE));
    }
    recorder.Submit();
    lastGpuMs = recorder.Timings().empty() || recorder.Timings()[0].gpuMs < 0
                    ? -1
                    : recorder.TotalGpuMs();

    std::vector<float> planar = buffers->out.DownloadFloats(outPixels * 3);
    std::vector<float> out(outPixels * 3);
    for (size_t i = 0; i < outPixels; ++i)
        for (int c = 0; c < 3; ++c) out[i * 3 + c] = planar[c * outPixels + i];
    return out;
}

}  // namespace mcd
