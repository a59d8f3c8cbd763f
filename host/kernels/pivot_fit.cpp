#include "host/kernels/pivot_fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <utility>

#include "host/error.h"
#include "host/kernels/pivot_ratio.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"
#include "pivot/fit.h"
#include "pivot/fit_spv.h"
#include "pivot/pivot.h"

namespace mcd {

// The fit writes and the gather reads a centre's planes as two vec4s per buffer.
static_assert(PIVOT_PLANES_PER_BUFFER == 8 && PIVOT_PLANES == 16);

void CheckPivotGuides(const char *what, int width, int height, const PivotGpuGuides &guides) {
    const vk::GpuImage *image = guides.image;
    if ((guides.normals || guides.ids) && !image)
        throw Error(fmt::format("{}: guides are switched on without a guide image", what),
                    ErrorKind::Internal);
    if (image && (image->width != width || image->height != height ||
                  image->channels != PIVOT_GUIDE_STRIDE))
        throw Error(fmt::format("{}: the guide image is {}x{}x{}, expected {}x{}x{}", what,
                                image->width, image->height, image->channels, width, height,
                                PIVOT_GUIDE_STRIDE),
                    ErrorKind::Internal);
}

void CheckPivotFitBuffers(const char *what, int width, int height, int channels,
                          const PivotFitBuffers &fits) {
    if (fits.Channels() != channels || int(fits.hi.size()) != channels)
        throw Error(fmt::format("{}: fit buffers of {} channels, expected {}", what,
                                fits.Channels(), channels),
                    ErrorKind::Internal);
    for (const auto *part : {&fits.lo, &fits.hi})
        for (const vk::GpuImage &fit : *part)
            if (fit.width != width || fit.height != height ||
                fit.channels != PIVOT_PLANES_PER_BUFFER)
                throw Error(fmt::format("{}: {} is {}x{}x{}, expected {}x{}x{}", what,
                                        fit.buffer.Name(), fit.width, fit.height, fit.channels,
                                        width, height, PIVOT_PLANES_PER_BUFFER),
                            ErrorKind::Internal);
}

Image PivotGuideBuffer(const Image &planes) {
    if (planes.channels != PIVOT_GUIDE_PLANES)
        throw Error(fmt::format("pivot guides: {} planes, expected {}", planes.channels,
                                PIVOT_GUIDE_PLANES),
                    ErrorKind::Internal);
    Image buffer(planes.width, planes.height, PIVOT_GUIDE_STRIDE);
    size_t pixels = planes.PixelCount();
    // The frame's distinct (object id, part id) pairs, by their bits (+0 makes -0 and 0 one
    // pair, as == does).
    std::unordered_map<uint64_t, int> labels;
    for (size_t i = 0; i < pixels; ++i) {
        float *out = &buffer.data[i * PIVOT_GUIDE_STRIDE];
        double n[3], len = 0;
        for (int k = 0; k < 3; ++k) {
            n[k] = planes.data[k * pixels + i];
            len += n[k] * n[k];
        }
        // A pixel's normal is the mean of its samples': shorter than 1 where they saw other
        // surfaces or none. Keep that length (the normal term compares it); normalise a
        // longer one.
        if (len > 0)
            for (int k = 0; k < 3; ++k) out[k] = float(n[k] / std::max(1.0, std::sqrt(len)));
        float object = planes.data[3 * pixels + i] + 0.f,
              part = planes.data[4 * pixels + i] + 0.f;
        uint32_t objectBits, partBits;
        std::memcpy(&objectBits, &object, sizeof(float));
        std::memcpy(&partBits, &part, sizeof(float));
        auto [it, added] =
            labels.try_emplace(uint64_t(objectBits) << 32 | partBits, int(labels.size()) + 1);
        // Labels are exact in float up to 2^24.
        if (it->second > (1 << 24))
            throw Error(
                "pivot guides: more distinct (object, part) id pairs than float "
                "labels can tell apart (2^24); tile the frame",
                ErrorKind::InvalidArgument);
        out[3] = len > 0 ? float(it->second) : -float(it->second);
    }
    return buffer;
}

Image PivotFitsOfBuffers(const Image &lo, const Image &hi, int channels) {
    int w = lo.width, h = lo.height;
    size_t centres = size_t(w) * h;
    Image fits(w, h, PIVOT_PLANES * channels);
    for (int c = 0; c < channels; ++c)
        for (size_t i = 0; i < centres; ++i)
            for (int p = 0; p < PIVOT_PLANES; ++p) {
                const Image &part = p < PIVOT_PLANES_PER_BUFFER ? lo : hi;
                fits.data[(size_t(p) * channels + c) * centres + i] =
                    part.data[(c * centres + i) * PIVOT_PLANES_PER_BUFFER +
                              p % PIVOT_PLANES_PER_BUFFER];
            }
    return fits;
}

void PivotBuffersOfFits(const Image &fits, int channels, Image *lo, Image *hi) {
    int w = fits.width, h = fits.height;
    size_t centres = size_t(w) * h;
    *lo = Image(w, h, PIVOT_PLANES_PER_BUFFER * channels);
    *hi = Image(w, h, PIVOT_PLANES_PER_BUFFER * channels);
    for (int c = 0; c < channels; ++c)
        for (size_t i = 0; i < centres; ++i)
            for (int p = 0; p < PIVOT_PLANES; ++p) {
                Image &part = p < PIVOT_PLANES_PER_BUFFER ? *lo : *hi;
                part.data[(c * centres + i) * PIVOT_PLANES_PER_BUFFER +
                          p % PIVOT_PLANES_PER_BUFFER] =
                    fits.data[(size_t(p) * channels + c) * centres + i];
            }
}

std::vector<Image> PivotZsnOf(const Image &z, const Image &s, const Image &nu,
                              const Image &level, const Image &noise, bool edgeInputs) {
    for (const Image *one : {&s, &nu, &level, &noise})
        if (one->width != z.width || one->height != z.height || one->channels != z.channels)
            throw Error("pivot: z, s, nu and level differ in shape", ErrorKind::Internal);
    std::vector<Image> zsn;
    const size_t pixels = z.PixelCount();
    const size_t n = edgeInputs ? PIVOT_ZSN_EDGE_PLANES : PIVOT_ZSN_PLANES;
    for (int c = 0; c < z.channels; ++c) {
        Image &one = zsn.emplace_back(z.width, z.height, int(n));
        for (size_t i = 0; i < pixels; ++i) {
            one.data[n * i] = z.Plane(c)[i];
            one.data[n * i + 1] = s.Plane(c)[i];
            one.data[n * i + 2] = nu.Plane(c)[i];
            if (!edgeInputs) continue;
            one.data[n * i + 3] = level.Plane(c)[i];
            one.data[n * i + 4] = noise.Plane(c)[i];
        }
    }
    return zsn;
}

PivotFitBuffers::PivotFitBuffers(vk::Context &context, int width, int height, int channels,
                                 const std::string &name) {
    for (int c = 0; c < channels; ++c) {
        lo.emplace_back(context, width, height, PIVOT_PLANES_PER_BUFFER,
                        fmt::format("{}Lo{}", name, c));
        hi.emplace_back(context, width, height, PIVOT_PLANES_PER_BUFFER,
                        fmt::format("{}Hi{}", name, c));
    }
}

namespace {

// The channels' buffers one after the other, as one image of 8 x channels planes.
Image Joined(const std::vector<vk::GpuImage> &parts) {
    const vk::GpuImage &first = parts.front();
    Image joined(first.width, first.height, PIVOT_PLANES_PER_BUFFER * int(parts.size()));
    size_t each = size_t(first.width) * first.height * PIVOT_PLANES_PER_BUFFER;
    for (size_t c = 0; c < parts.size(); ++c)
        parts[c].buffer.Download(joined.data.data() + c * each, each * sizeof(float));
    return joined;
}

void Split(const Image &joined, std::vector<vk::GpuImage> &parts) {
    size_t each = size_t(joined.width) * joined.height * PIVOT_PLANES_PER_BUFFER;
    for (size_t c = 0; c < parts.size(); ++c)
        parts[c].buffer.Upload(joined.data.data() + c * each, each * sizeof(float));
}

}  // namespace

Image PivotFitBuffers::Download() const {
    return PivotFitsOfBuffers(Joined(lo), Joined(hi), Channels());
}

void PivotFitBuffers::Upload(const Image &fits) {
    Image joinedLo, joinedHi;
    PivotBuffersOfFits(fits, Channels(), &joinedLo, &joinedHi);
    Split(joinedLo, lo);
    Split(joinedHi, hi);
}

Image PivotFitBuffers::Radii() const {
    const vk::GpuImage &first = hi.front();
    Image radii(first.width, first.height, Channels());
    const size_t centres = radii.PixelCount();
    // Blocks of centres through one small buffer, reused: the radius is one float of a
    // centre's eight, and a copy of the whole buffer would fault in fresh pages for all eight.
    // A staged buffer is read whole: there each read is a submission and a wait.
    const size_t block = first.buffer.Mapped() ? std::min(centres, kPivotRadiiBlock)
                                               : std::max<size_t>(centres, 1);
    std::vector<float> planes(block * PIVOT_PLANES_PER_BUFFER);
    constexpr int kRadius = PIVOT_PLANES - 1 - PIVOT_PLANES_PER_BUFFER;
    for (int c = 0; c < Channels(); ++c) {
        float *plane = radii.Plane(c);
        for (size_t begin = 0; begin < centres; begin += block) {
            const size_t n = std::min(block, centres - begin);
            hi[size_t(c)].buffer.Download(planes.data(),
                                          n * PIVOT_PLANES_PER_BUFFER * sizeof(float),
                                          begin * PIVOT_PLANES_PER_BUFFER * sizeof(float));
            for (size_t i = 0; i < n; ++i)
                plane[begin + i] = planes[i * PIVOT_PLANES_PER_BUFFER + kRadius];
        }
    }
    return radii;
}

vk::KernelDesc PivotFitKernel(bool normals, bool ids, int zsnTexels) {
    return {"pivot_fit",
            k_pivot_fit_spv,
            sizeof(k_pivot_fit_spv),
            PIVOT_FIT_BINDINGS,
            sizeof(shader::PivotFitPush),
            {{PIVOT_SPEC_NORMALS, normals ? 1 : 0},
             {PIVOT_SPEC_IDS, ids ? 1 : 0},
             {PIVOT_SPEC_ZSN_TEXELS, zsnTexels}},
            (1u << PIVOT_FIT_ZSN) | (1u << PIVOT_FIT_GUIDES),
            (1u << PIVOT_FIT_ZSN) | (1u << PIVOT_FIT_GUIDES)};
}

void RecordPivotFit(vk::Context &context, vk::Recorder &recorder,
                    const std::vector<vk::GpuImage> &zsn, const PivotGpuGuides &guides,
                    const PivotFitSettings &settings, PivotFitBuffers &fits, int rowBase,
                    int rows) {
    if (zsn.empty() || zsn.size() > PIVOT_MAX_CHANNELS)
        throw Error(fmt::format("pivot fit: {} packed z, s, nu images; 1 to {} colour channels",
                                zsn.size(), PIVOT_MAX_CHANNELS),
                    ErrorKind::Internal);
    int w = zsn[0].width, h = zsn[0].height, channels = int(zsn.size());
    int zsnTexels = CheckPivotZsn("pivot fit", w, h, channels, zsn);
    CheckPivotZsnHoldsEdge("pivot fit", zsnTexels, settings.edge);
    CheckPivotGuides("pivot fit", w, h, guides);
    CheckPivotFitBuffers("pivot fit", w, h, channels, fits);
    if (rowBase < 0 || rows < 1 || rowBase + rows > h)
        throw Error(fmt::format("pivot fit: rows {}..{} of a {}-row image", rowBase,
                                rowBase + rows - 1, h),
                    ErrorKind::Internal);
    if (settings.maxRadius < 2 || settings.maxRadius > 64)
        throw Error(fmt::format("pivot fit: the maximum radius is {}; 2..64 allowed",
                                settings.maxRadius),
                    ErrorKind::InvalidArgument);
    const vk::Kernel &kernel =
        context.GetKernel(PivotFitKernel(guides.normals, guides.ids, zsnTexels));
    for (int c = 0; c < channels; ++c) {
        shader::PivotFitPush push{w,
                                  h,
                                  settings.maxRadius,
                                  settings.targetNoise,
                                  settings.goodNoise * settings.goodNoise,
                                  settings.disagreement,
                                  settings.k,
                                  settings.sigmaWeight,
                                  rowBase,
                                  settings.edge};
        // Absent guides are compiled out; zsn stands in for their binding.
        const vk::Buffer &packed = zsn[size_t(c)].buffer;
        recorder.Dispatch(kernel, "pivot.fit",
                          {{PIVOT_FIT_ZSN, &packed, vk::Access::Read},
                           {PIVOT_FIT_GUIDES, guides.image ? &guides.image->buffer : &packed,
                            vk::Access::Read},
                           {PIVOT_FIT_LO, &fits.lo[c].buffer, vk::Access::Write},
                           {PIVOT_FIT_HI, &fits.hi[c].buffer, vk::Access::Write}},
                          push, uint32_t((w + PIVOT_LOCAL_SIZE - 1) / PIVOT_LOCAL_SIZE),
                          uint32_t(rows), 1);
    }
}

}  // namespace mcd
