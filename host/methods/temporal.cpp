#include "host/methods/temporal.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <tuple>

#include "host/error.h"
#include "host/kernels/temporal_finish.h"
#include "host/kernels/temporal_fold.h"
#include "host/kernels/temporal_match.h"
#include "host/vk/gpu_image.h"
#include "shaders/temporal/finish.h"
#include "shaders/temporal/temporal.h"

namespace mcd {

bool TemporalGathers(const std::string &layer) {
    return layer == "min" || layer == "max" || layer == "hist" || layer == "direct" ||
           layer == "indirect";
}

namespace {

bool HasMoments(const std::string &layer) {
    return layer == "direct" || layer == "indirect";
}

// The frames of the window that are folded, and how.
struct Window {
    const TemporalFrameLayers *current = nullptr;
    std::vector<const TemporalFrameLayers *> sides[2];  // earlier, later: nearest first
    std::vector<std::string> gathered;                  // of TemporalGathers, in order
    bool motion = false, spp = false, pooled = false;
    std::map<std::string, bool> layerPooled;  // direct, indirect: from their variances
    std::vector<std::string> warnings;

    // Whether `layer`'s variance is folded from the frames' own (direct, indirect).
    bool LayerPooled(const std::string &layer) const {
        auto it = layerPooled.find(layer);
        return it != layerPooled.end() && it->second;
    }

    template <class F>
    bool All(F has) const {
        if (!has(*current)) return false;
        for (const auto &side : sides)
            for (const TemporalFrameLayers *f : side)
                if (!has(*f)) return false;
        return true;
    }
};

// Why `f` cannot be folded with `current` ("" when it can): a layer the current frame
// gathers is missing, or a shape differs.
std::string Unfoldable(const TemporalFrameLayers &current, const TemporalFrameLayers &f,
                       const std::vector<std::string> &gathered) {
    const Image &c = *current.color;
    if (!f.color) return "it has no color";
    if (!f.color->SameShape(c))
        return fmt::format("its color is {}x{}x{}, the current frame's {}x{}x{}",
                           f.color->width, f.color->height, f.color->channels, c.width,
                           c.height, c.channels);
    for (const std::string &name : gathered) {
        auto it = f.layers.find(name);
        if (it == f.layers.end() || !it->second) return "it has no " + name;
        if (!it->second->SameShape(*current.layers.at(name))) return "its " + name + " differs";
    }
    return "";
}

// A layer of the frame's size and `channels` channels, or null.
const Image *Fitting(const Image *image, const Image &color, int channels) {
    if (!image || image->width != color.width || image->height != color.height ||
        image->channels != channels)
        return nullptr;
    return image;
}

Window PlanWindow(const std::vector<TemporalFrameLayers> &frames,
                  const TemporalParams &params) {
    Window w;
    std::map<int, const TemporalFrameLayers *> byOffset;
    for (const TemporalFrameLayers &f : frames) {
        if (!byOffset.emplace(f.offset, &f).second)
            throw Error(fmt::format("temporal: two frames at offset {}", f.offset),
                        ErrorKind::InvalidArgument);
    }
    auto it = byOffset.find(0);
    if (it == byOffset.end() || !it->second->color)
        throw Error("temporal: the window has no current frame (offset 0) with a color",
                    ErrorKind::InvalidArgument);
    w.current = it->second;
    const Image &color = *w.current->color;
    if (color.channels < 1 || color.channels > 4 || color.Empty())
        throw Error(fmt::format("temporal: the color has {} channels; 1 to 4 are gathered",
                                color.channels),
                    ErrorKind::InvalidArgument);
    for (const auto &[name, image] : w.current->layers)
        if (image && TemporalGathers(name)) {
            if (image->width != color.width || image->height != color.height)
                throw Error(
                    fmt::format("temporal: the current frame's {} is not of its size", name),
                    ErrorKind::InvalidArgument);
            w.gathered.push_back(name);
        }
    for (int side = 0; side < 2; ++side)
        for (int k = 1; k <= params.radius; ++k) {
            int offset = side == 0 ? -k : k;
            auto found = byOffset.find(offset);
            if (found == byOffset.end()) break;
            std::string why = Unfoldable(*w.current, *found->second, w.gathered);
            if (!why.empty()) {
                w.warnings.push_back(fmt::format(
                    "temporal: the frame at offset {} is left out, and those beyond it: {}",
                    offset, why));
                break;
            }
            w.sides[side].push_back(found->second);
        }
    auto fits = [&](const Image *image, int channels) {
        return Fitting(image, color, channels);
    };
    w.motion =
        w.All([&](const TemporalFrameLayers &f) { return fits(f.motion, 4) != nullptr; });
    w.spp = w.All([&](const TemporalFrameLayers &f) { return fits(f.spp, 1) != nullptr; });
    w.pooled =
        params.variance == TemporalVariance::Auto && w.All([&](const TemporalFrameLayers &f) {
            return fits(f.variance, color.channels) != nullptr;
        });
    for (const std::string &name : w.gathered)
        if (HasMoments(name))
            w.layerPooled[name] =
                params.variance == TemporalVariance::Auto &&
                w.All([&](const TemporalFrameLayers &f) {
                    auto v = f.layers.find(name + ".variance");
                    return v != f.layers.end() && fits(v->second, f.layers.at(name)->channels);
                });
    bool someMotion = fits(w.current->motion, 4) != nullptr;
    if (!w.motion && someMotion)
        w.warnings.push_back(
            "temporal: not every frame of the window has motion vectors: the camera is taken "
            "as still");
    return w;
}

// The features present in a frame (TEMPORAL_HAS_*), packed into `out` (temporal.h's
// planes; absent ones 0).
int PackFeatures(const TemporalFrameLayers &f, Image &out) {
    const Image &color = *f.color;
    out = Image(color.width, color.height, TEMPORAL_FEATURE_PLANES);
    int mask = 0;
    auto copy = [&](const Image *image, int channels, int plane, int bit) {
        if (!Fitting(image, color, channels)) return;
        std::copy(image->data.begin(), image->data.end(), out.Plane(plane));
        mask |= bit;
    };
    copy(f.normal, 3, TEMPORAL_FEATURE_NORMAL, TEMPORAL_HAS_NORMAL);
    copy(f.depth, 1, TEMPORAL_FEATURE_DEPTH, TEMPORAL_HAS_DEPTH);
    copy(f.albedo, 3, TEMPORAL_FEATURE_ALBEDO, TEMPORAL_HAS_ALBEDO);
    copy(f.objectId, 1, TEMPORAL_FEATURE_ID, TEMPORAL_HAS_ID);
    return mask;
}

// One frame's images on the GPU: the current frame's for the whole run, a neighbour's
// reused by each neighbour in turn.
struct FrameGpu {
    vk::GpuImage features, color, variance, spp, motion;
    std::map<std::string, vk::GpuImage> layers;  // gathered, and direct/indirect variances
    int mask = 0;

    FrameGpu(vk::Context &context, const Window &w, const std::string &prefix) {
        const Image &c = *w.current->color;
        auto make = [&](int channels, const std::string &name) {
            return vk::GpuImage(context, c.width, c.height, channels, prefix + name);
        };
        features = make(TEMPORAL_FEATURE_PLANES, "features");
        color = make(c.channels, "color");
        if (w.pooled) variance = make(c.channels, "variance");
        if (w.spp) spp = make(1, "spp");
        if (w.motion) motion = make(4, "motion");
        for (const std::string &name : w.gathered) {
            int channels = w.current->layers.at(name)->channels;
            layers.emplace(name, make(channels, name));
            if (w.LayerPooled(name))
                layers.emplace(name + ".variance", make(channels, name + ".variance"));
        }
    }

    void Upload(const TemporalFrameLayers &f, const Window &w) {
        Image packed;
        mask = PackFeatures(f, packed);
        features.Upload(packed);
        color.Upload(*f.color);
        if (w.pooled) variance.Upload(*f.variance);
        if (w.spp) spp.Upload(*f.spp);
        if (w.motion) motion.Upload(*f.motion);
        for (auto &[name, image] : layers) image.Upload(*f.layers.at(name));
    }
};

// The running state of the gathered frame, and the chain's positions.
struct State {
    vk::GpuImage counts, moments, pooled, sums[2], halfCounts[2], weight, positions[3];
    std::map<std::string, vk::GpuImage> layers, layerPooled;
    bool halfStarted[2] = {false, false};

    State(vk::Context &context, const Window &w) {
        const Image &c = *w.current->color;
        int C = c.channels;
        auto make = [&](int channels, const std::string &name) {
            return vk::GpuImage(context, c.width, c.height, channels, "temporal." + name);
        };
        counts = make(2, "counts");
        moments = make(2 * C, "moments");
        if (w.pooled) pooled = make(C, "pooled");
        for (int k = 0; k < 2; ++k) {
            sums[k] = make(C, fmt::format("half{}.sum", k));
            halfCounts[k] = make(2, fmt::format("half{}.counts", k));
        }
        weight = make(1, "weight");
        for (int k = 0; k < 3; ++k) positions[k] = make(2, fmt::format("positions{}", k));
        for (const std::string &name : w.gathered) {
            int channels = w.current->layers.at(name)->channels;
            layers.emplace(name, make(HasMoments(name) ? 2 * channels : channels, name));
            if (w.LayerPooled(name))
                layerPooled.emplace(name, make(channels, name + ".pooled"));
        }
    }
};

// Fold one frame's layers (matched: weights in state.weight, positions in `position`)
// into the state; the current frame's first, read at the pixels themselves.
void FoldFrame(StagedRun &run, const Window &w, State &s, const FrameGpu &f,
               const vk::GpuImage &position, bool current, int parity) {
    vk::Context &context = run.Context();
    vk::Recorder &recorder = run.Recorder();
    auto fold = [&](const vk::GpuImage &value, TemporalFoldMode mode, int power, bool first,
                    vk::GpuImage &state) {
        RecordTemporalFold(context, recorder, value, position, s.weight, s.counts,
                           {mode, power, first, current}, state);
    };
    fold(f.color, TemporalFoldMode::Moments, 1, current, s.moments);
    if (w.pooled) fold(f.variance, TemporalFoldMode::Sum, 2, current, s.pooled);
    fold(f.color, TemporalFoldMode::Sum, 1, !s.halfStarted[parity], s.sums[parity]);
    fold(f.color, TemporalFoldMode::Count, 1, !s.halfStarted[parity], s.halfCounts[parity]);
    s.halfStarted[parity] = true;
    for (const std::string &name : w.gathered) {
        const vk::GpuImage &value = f.layers.at(name);
        vk::GpuImage &state = s.layers.at(name);
        if (HasMoments(name)) {
            fold(value, TemporalFoldMode::Moments, 1, current, state);
            if (w.LayerPooled(name))
                fold(f.layers.at(name + ".variance"), TemporalFoldMode::Sum, 2, current,
                     s.layerPooled.at(name));
        } else if (name == "hist") {
            fold(value, TemporalFoldMode::Sum, 0, current, state);
        } else {
            fold(value, name == "min" ? TemporalFoldMode::Min : TemporalFoldMode::Max, 1,
                 current, state);
        }
    }
    // Last: the folds above read the weights gathered before this frame.
    fold(f.color, TemporalFoldMode::Count, 1, current, s.counts);
}

TemporalMatchTest MatchTest(const TemporalParams &params, int mask) {
    TemporalMatchTest test;
    test.features = mask;
    test.normalCos = float(std::cos(double(params.normalAngle) * std::numbers::pi / 180));
    test.depthRel = params.depthTolerance;
    test.albedoRel = params.albedoTolerance;
    test.motionTol = params.motionTolerance;
    return test;
}

TemporalMatchFrame MatchFrame(const FrameGpu &f, const Window &w) {
    return {&f.features, &f.color, w.spp ? &f.spp : nullptr, w.motion ? &f.motion : nullptr};
}

// Walk one side's chain (direction -1 or +1): match each frame in turn, fold what was
// accepted, and note how much.
void FoldSide(StagedRun &run, const Window &w, const TemporalParams &params, State &s,
              const FrameGpu &current, FrameGpu &neighbour, int direction,
              TemporalGathered &result) {
    vk::Context &context = run.Context();
    const auto &side = w.sides[direction < 0 ? 0 : 1];
    if (side.empty()) return;
    // The chain starts from the current frame's own motion.
    int previous = 0, here = 1, next = 2;
    RecordTemporalMatch(context, run.Recorder(), current.features, MatchFrame(current, w),
                        s.positions[previous], s.positions[previous], true, false, direction,
                        MatchTest(params, 0), s.weight, s.positions[here]);
    for (size_t k = 0; k < side.size(); ++k) {
        run.Submit();
        neighbour.Upload(*side[k], w);
        int mask = current.mask & neighbour.mask;
        RecordTemporalMatch(context, run.Recorder(), current.features, MatchFrame(neighbour, w),
                            s.positions[previous], s.positions[here], false, k == 0, direction,
                            MatchTest(params, mask), s.weight, s.positions[next]);
        FoldFrame(run, w, s, neighbour, s.positions[here], false, int(k + 1) % 2);
        run.Submit();
        Image weight = s.weight.Download();
        size_t accepted = std::count_if(weight.data.begin(), weight.data.end(),
                                        [](float v) { return v > 0; });
        result.offsets.push_back(side[k]->offset);
        result.acceptedPercent.push_back(100.0 * double(accepted) / double(weight.Size()));
        std::tie(previous, here, next) = std::make_tuple(here, next, previous);
    }
}

// Finish a moments state into its mean and variance (and with halves the half-buffers):
// the output's planes as in RecordTemporalFinish.
Image FinishLayer(StagedRun &run, const TemporalParams &params, const State &s,
                  const vk::GpuImage &moments, const vk::GpuImage *pooled,
                  const vk::GpuImage &raw, bool halves) {
    TemporalFinishInputs in{&moments, &s.counts, &raw, pooled};
    if (halves) in.sum0 = &s.sums[0], in.counts0 = &s.halfCounts[0];
    if (halves) in.sum1 = &s.sums[1], in.counts1 = &s.halfCounts[1];
    vk::GpuImage out(run.Context(), raw.width, raw.height, (halves ? 4 : 2) * raw.channels,
                     "temporal.finished");
    RecordTemporalFinish(run.Context(), run.Recorder(), in, params.fillRadius, out);
    run.Submit();
    return out.Download();
}

// Planes [first, first + count) of `image`.
Image Planes(const Image &image, int first, int count) {
    Image out(image.width, image.height, count);
    std::copy(image.Plane(first), image.Plane(first) + out.Size(), out.data.begin());
    return out;
}

void CheckParams(const TemporalParams &p) {
    if (p.radius < 0 || p.radius > 16)
        throw Error(fmt::format("temporal: radius {} outside [0, 16]", p.radius),
                    ErrorKind::InvalidArgument);
    if (!(p.normalAngle >= 0 && p.normalAngle <= 180))
        throw Error(fmt::format("temporal: normal angle {} outside [0, 180]", p.normalAngle),
                    ErrorKind::InvalidArgument);
    for (float t : {p.depthTolerance, p.albedoTolerance, p.motionTolerance})
        if (!(t >= 0) || !std::isfinite(t))
            throw Error(fmt::format("temporal: tolerance {} is not a number >= 0", t),
                        ErrorKind::InvalidArgument);
    if (p.fillRadius < 0 || p.fillRadius > TEMPORAL_FINISH_MAX_RADIUS)
        throw Error(fmt::format("temporal: fill radius {} outside [0, {}]", p.fillRadius,
                                TEMPORAL_FINISH_MAX_RADIUS),
                    ErrorKind::InvalidArgument);
}

std::string PlanLine(const Window &w, const TemporalGathered &r, int mask) {
    std::string accepted;
    for (size_t k = 0; k < r.offsets.size(); ++k)
        accepted +=
            fmt::format("{}{:+d} {:.1f}%", k ? ", " : "", r.offsets[k], r.acceptedPercent[k]);
    std::string features;
    const char *names[] = {"normal", "depth", "albedo", "object id"};
    for (int bit = 0; bit < 4; ++bit)
        if (mask & (1 << bit))
            features += (features.empty() ? "" : ", ") + std::string(names[bit]);
    return fmt::format(
        "temporal: gathered with {} neighbours (accepted: {}); {}; features compared: {}; "
        "variance {}",
        r.offsets.size(), accepted.empty() ? "none" : accepted,
        w.motion ? "positions through the motion vectors"
                 : "a still camera (no motion vectors)",
        features.empty() ? "none" : features,
        w.pooled ? "from the frames' own variances" : "from the spread of the frames");
}

}  // namespace

TemporalGathered TemporalGather(vk::Context &context,
                                const std::vector<TemporalFrameLayers> &frames,
                                const TemporalParams &params, const RunSetup &setup) {
    CheckParams(params);
    Window w = PlanWindow(frames, params);
    StagedRun run(context, setup.keepStages);
    FrameGpu current(context, w, "temporal.current.");
    FrameGpu neighbour(context, w, "temporal.neighbour.");
    State s(context, w);
    current.Upload(*w.current, w);
    // The current frame's own sample: its weight (a finite colour) and its layers.
    RecordTemporalMatch(context, run.Recorder(), current.features, MatchFrame(current, w),
                        s.positions[0], s.positions[0], true, false, -1, MatchTest(params, 0),
                        s.weight, s.positions[1]);
    FoldFrame(run, w, s, current, s.positions[0], true, 0);
    TemporalGathered result;
    int mask = current.mask;
    for (int direction : {-1, 1}) {
        FoldSide(run, w, params, s, current, neighbour, direction, result);
        for (const TemporalFrameLayers *f : w.sides[direction < 0 ? 0 : 1]) {
            Image packed;
            mask &= PackFeatures(*f, packed);
        }
    }
    const Image &color = *w.current->color;
    int C = color.channels;
    Image out = FinishLayer(run, params, s, s.moments, w.pooled ? &s.pooled : nullptr,
                            current.color, true);
    result.image = Planes(out, 0, C);
    result.layers.push_back({"color", result.image});
    result.layers.push_back({"variance", Planes(out, C, C)});
    result.layers.push_back({"half0.color", Planes(out, 2 * C, C)});
    result.layers.push_back({"half1.color", Planes(out, 3 * C, C)});
    Image counts = s.counts.Download();
    if (w.spp) result.layers.push_back({"spp", Planes(counts, 0, 1)});
    result.frames = Planes(counts, 1, 1);
    for (const std::string &name : w.gathered) {
        if (!HasMoments(name)) {
            result.layers.push_back({name, s.layers.at(name).Download()});
            continue;
        }
        bool pooled = w.LayerPooled(name);
        Image finished = FinishLayer(run, params, s, s.layers.at(name),
                                     pooled ? &s.layerPooled.at(name) : nullptr,
                                     current.layers.at(name), false);
        int channels = finished.channels / 2;
        result.layers.push_back({name, Planes(finished, 0, channels)});
        result.layers.push_back({name + ".variance", Planes(finished, channels, channels)});
    }
    result.pooled = w.pooled;
    result.motion = w.motion;
    run.Plan(PlanLine(w, result, mask));
    for (const std::string &warning : w.warnings) run.Warn(warning);
    run.Finish(result);
    return result;
}

}  // namespace mcd
