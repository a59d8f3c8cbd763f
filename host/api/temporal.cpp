// mcd::Temporal: the temporal mode's parameter table over TemporalParams
// (host/params/temporal.h) and the gather (host/methods/temporal.h) on mcd::Frames.
#include "mcdenoise/temporal.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "host/api/device.h"
#include "host/api/front_end.h"
#include "host/io/layer_names.h"
#include "host/methods/temporal.h"

namespace mcd {

namespace {

std::vector<api::ParamDef<TemporalParams>> Defs() {
    using P = TemporalParams;
    return {
        api::IntParam<P>("temporal-radius",
                         "sequences: frames gathered before and after each frame (0: each "
                         "frame alone)",
                         &P::radius, 0, 16),
        api::FloatParam<P>("temporal-normal",
                           "sequences: a neighbour's sample is rejected where its normal is "
                           "more than this many degrees off the frame's",
                           &P::normalAngle, 0, 180),
        api::FloatParam<P>("temporal-depth",
                           "sequences: ... or its depth differs by more than this fraction",
                           &P::depthTolerance, 0, 10),
        api::FloatParam<P>("temporal-albedo",
                           "sequences: ... or an albedo channel by more than this fraction",
                           &P::albedoTolerance, 0, 10),
        api::FloatParam<P>("temporal-motion",
                           "sequences: ... or its motion vector back does not return within "
                           "this many pixels of where it came from (0: not checked)",
                           &P::motionTolerance, 0, 1000),
        api::EnumParam<P, TemporalVariance>(
            "temporal-variance",
            "sequences: the gathered frame's variance from the frames' own variance layers "
            "when all have one (auto) or from the spread of the frames (spread)",
            &P::variance,
            {{"auto", TemporalVariance::Auto}, {"spread", TemporalVariance::Spread}}),
        api::IntParam<P>("temporal-fill",
                         "sequences: where one frame's sample alone was accepted, the "
                         "spread's variance pooled over this radius",
                         &P::fillRadius, 0, 8)};
}

const std::vector<ParamInfo> &Infos() {
    static const std::vector<ParamInfo> infos = [] {
        std::vector<ParamInfo> list;
        for (const api::ParamDef<TemporalParams> &def : Defs()) {
            ParamInfo info = def.info;
            info.defaultValue = def.get(TemporalParams());
            info.method = "temporal";
            list.push_back(info);
        }
        return list;
    }();
    return infos;
}

const ParamInfo &Info(const std::string &name) {
    for (const ParamInfo &info : Infos())
        if (info.name == name) return info;
    throw Error(fmt::format("temporal has no parameter '{}'", name),
                ErrorKind::InvalidArgument);
}

// Refuse a value of the wrong type, outside the range or not among the choices.
void Check(const ParamInfo &info, ParamValue &value) {
    if (info.type == ParamType::Float && std::holds_alternative<int>(value))
        value = float(std::get<int>(value));
    bool typed = (info.type == ParamType::Int && std::holds_alternative<int>(value)) ||
                 (info.type == ParamType::Float && std::holds_alternative<float>(value)) ||
                 (info.type == ParamType::String && std::holds_alternative<std::string>(value));
    if (!typed)
        throw Error(
            fmt::format("temporal: parameter '{}' takes a value of another type", info.name),
            ErrorKind::InvalidArgument);
    double v = info.type == ParamType::Int     ? double(std::get<int>(value))
               : info.type == ParamType::Float ? double(std::get<float>(value))
                                               : 0;
    if (info.type != ParamType::String && !(v >= info.min && v <= info.max))
        throw Error(fmt::format("temporal: parameter '{}' is {}, outside [{}, {}]", info.name,
                                v, info.min, info.max),
                    ErrorKind::InvalidArgument);
    if (info.type == ParamType::String &&
        std::find(info.choices.begin(), info.choices.end(), std::get<std::string>(value)) ==
            info.choices.end())
        throw Error(fmt::format("temporal: {} takes {}, not '{}'", info.name,
                                api::OrList(info.choices), std::get<std::string>(value)),
                    ErrorKind::InvalidArgument);
}

// Layers of a sample statistic the gather cannot fold: left out of the gathered frame.
bool Ungathered(const std::string &name) {
    return name.rfind("partial", 0) == 0 || name == "remainder" || name == "zhist" ||
           name == "color.unfiltered";
}

// Planar images of a window's frames: owned layers by address, borrowed ones copied.
class WindowImages {
  public:
    const Image *Get(const Frame &frame, const std::string &name) {
        if (auto it = frame.layers.find(name); it != frame.layers.end()) return &it->second;
        if (!frame.views.count(name)) return nullptr;
        copies.push_back(std::make_unique<Image>(frame.Copy(name)));
        return copies.back().get();
    }

    TemporalFrameLayers Layers(const Frame &frame, int offset) {
        TemporalFrameLayers f;
        f.offset = offset;
        f.color = Get(frame, "color");
        f.variance = Get(frame, "variance");
        f.spp = Get(frame, "spp");
        f.motion = Get(frame, "motion");
        f.normal = Get(frame, "normal");
        f.depth = Get(frame, "depth");
        f.albedo = Get(frame, "albedo");
        f.objectId = Get(frame, "objectId");
        for (const std::string &name : frame.Names())
            if (TemporalGathers(name) || name == "direct.variance" ||
                name == "indirect.variance")
                f.layers[name] = Get(frame, name);
        return f;
    }

  private:
    std::vector<std::unique_ptr<Image>> copies;
};

// The current frame's layers with the gathered ones in their place.
Frame GatheredFrame(const Frame &current, TemporalGathered &g, std::vector<std::string> *plan) {
    Frame out(current.width, current.height);
    out.path = current.path;
    out.metadata = current.metadata;
    std::vector<std::string> dropped;
    for (auto &[name, image] : g.layers) out.layers[name] = std::move(image);
    for (const std::string &name : current.Names()) {
        if (out.layers.count(name)) continue;
        if (Ungathered(name) || name == "half0.color" || name == "half1.color" ||
            io::IsHalf0LayerName(name) ||
            (name == "variance" || name == "direct.variance" || name == "indirect.variance")) {
            dropped.push_back(name);
            continue;
        }
        out.layers[name] = current.Copy(name);
    }
    if (!dropped.empty())
        plan->push_back(fmt::format(
            "temporal: left out of the gathered frame (statistics of the frame's own samples "
            "that were not gathered): {}",
            fmt::join(dropped, ", ")));
    std::string offsets;
    for (int offset : g.offsets)
        offsets += fmt::format("{}{:+d}", offsets.empty() ? "" : ",", offset);
    out.metadata["mcd:temporalOffsets"] = offsets;
    return out;
}

}  // namespace

struct Temporal::Impl {
    TemporalParams params;
};

Temporal::Temporal() : impl(std::make_unique<Impl>()) {}
Temporal::~Temporal() = default;
Temporal::Temporal(const Temporal &other) : impl(std::make_unique<Impl>(*other.impl)) {}
Temporal &Temporal::operator=(const Temporal &other) {
    if (this != &other) impl = std::make_unique<Impl>(*other.impl);
    return *this;
}
Temporal::Temporal(Temporal &&) noexcept = default;
Temporal &Temporal::operator=(Temporal &&) noexcept = default;

const std::vector<ParamInfo> &Temporal::Params() const {
    return Infos();
}

bool Temporal::HasParam(const std::string &name) const {
    for (const ParamInfo &info : Infos())
        if (info.name == name) return true;
    return false;
}

void Temporal::Set(const std::string &name, ParamValue value) {
    Check(Info(name), value);
    for (const api::ParamDef<TemporalParams> &def : Defs())
        if (def.info.name == name) def.set(impl->params, value);
}

void Temporal::SetText(const std::string &name, const std::string &text) {
    const ParamInfo &info = Info(name);
    char *end = nullptr;
    if (info.type == ParamType::String) return Set(name, text);
    if (info.type == ParamType::Int) {
        long v = std::strtol(text.c_str(), &end, 10);
        if (end != text.c_str() && *end == 0 && v >= -(1l << 30) && v <= (1l << 30))
            return Set(name, ParamValue(int(v)));
    } else {
        float v = std::strtof(text.c_str(), &end);
        if (end != text.c_str() && *end == 0) return Set(name, ParamValue(v));
    }
    throw Error(fmt::format("temporal: parameter '{}' takes {}, not '{}'", name,
                            info.type == ParamType::Int ? "an integer" : "a number", text),
                ErrorKind::InvalidArgument);
}

ParamValue Temporal::Get(const std::string &name) const {
    Info(name);
    for (const api::ParamDef<TemporalParams> &def : Defs())
        if (def.info.name == name) return def.get(impl->params);
    return {};
}

int Temporal::Radius() const {
    return impl->params.radius;
}

std::vector<std::string> Temporal::Uses() const {
    return {"color",
            "variance",
            "spp",
            "motion",
            "normal",
            "depth",
            "albedo",
            "objectId",
            "min",
            "max",
            "hist",
            "direct",
            "indirect",
            "direct.variance",
            "indirect.variance"};
}

TemporalResult Temporal::Gather(Device &device,
                                const std::map<int, const Frame *> &window) const {
    auto start = std::chrono::steady_clock::now();
    auto it = window.find(0);
    if (it == window.end() || !it->second)
        throw Error("temporal: the window has no current frame (offset 0)",
                    ErrorKind::InvalidArgument);
    const Frame &current = *it->second;
    if (!current.Has("color"))
        throw Error(fmt::format("temporal: {} has no color layer",
                                current.path.empty() ? "the frame" : current.path),
                    ErrorKind::MissingLayer);
    WindowImages images;
    std::vector<TemporalFrameLayers> frames;
    for (const auto &[offset, frame] : window) {
        if (!frame || std::abs(offset) > impl->params.radius) continue;
        if (frame->width != current.width || frame->height != current.height)
            throw Error(
                fmt::format("temporal: the frame at offset {} ({}) is {}x{}, the current "
                            "frame {}x{}",
                            offset, frame->path, frame->width, frame->height, current.width,
                            current.height),
                ErrorKind::InvalidArgument);
        frames.push_back(images.Layers(*frame, offset));
    }
    TemporalGathered g = TemporalGather(api::ContextOf(device), frames, impl->params);
    TemporalResult result;
    result.plan = std::move(g.plan);
    result.warnings = std::move(g.warnings);
    for (const vk::DispatchTiming &t : g.timings) result.timings.push_back({t.label, t.gpuMs});
    result.frame = GatheredFrame(current, g, &result.plan);
    result.frames = std::move(g.frames);
    result.offsets = g.offsets;
    result.acceptedPercent = g.acceptedPercent;
    result.wallMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
    return result;
}

}  // namespace mcd
