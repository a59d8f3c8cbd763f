// mcd::Method: a front end by name, the parameters every method shares (demodulation, the
// non-finite policy, the kept mean), `auto`, and the run around the front end: inputs,
// ledger, wall time.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "host/api/cancel.h"
#include "host/api/device.h"
#include "host/api/front_end.h"
#include "host/api/method_auto.h"
#include "host/api/registry.h"
#include "host/api/tiled_run.h"
#include "host/api/views.h"
#include "host/io/hints.h"
#include "host/methods/pivot.h"

namespace mcd {

namespace {

// How far a method's output on a frame without sample statistics may move the frame's mean
// luminance before its output is scaled back: half the 2% auto is held to
// (docs/methods/auto.md), so that an output is not left a percent or two darker than the
// frame. auto's nfor alone reads it too.
constexpr float kMeanShift = 0.01f;

// The parameters of mcd::Method itself, shared by every method.
struct CommonParams {
    std::string demodulate, nonFinite = "refuse";
    float alphaRim = 0.02f, maxMeanShift = kMeanShift;
};

std::vector<api::ParamDef<CommonParams>> CommonDefs() {
    return {
        api::ChoiceParam("demodulate",
                         "divide the frame by its pivot or albedo layer before the method "
                         "and multiply back after (Ershov et al. 4.1: filter z = color / "
                         "pivot with any method but pivot; rhf then needs the frame's zhist "
                         "layer, from render --layers zhist, and the pivot)",
                         &CommonParams::demodulate, {"", "pivot", "albedo"}),
        api::ChoiceParam("non-finite",
                         "NaN/Inf input values: refuse (stop, naming the layer, the count "
                         "and the first pixel) or zero (replace them with 0 and warn so)",
                         &CommonParams::nonFinite, {"refuse", "zero"}),
        api::FloatParam("alpha-rim",
                        "a fully transparent pixel (alpha 0) beside covered ones takes this "
                        "share of the output colour and of the alpha of each of its 4 "
                        "neighbours of alpha above 0, which keep the rest: the coverage the "
                        "renderer's pixel filter gives a pixel beside an edge, which few "
                        "samples draw (docs/frames.md); 0: it keeps the frame's colour and "
                        "alpha. Runs only where the alpha is delivered beside the colour (not "
                        "into an output without an alpha channel, nor with "
                        "--overwrite-input, which keeps the file's alpha); at most 0.2, so "
                        "an isolated covered pixel keeps a fifth of itself",
                        &CommonParams::alphaRim, 0, 0.2),
        api::FloatParam(
            "max-mean-shift",
            "on a frame without sample statistics (no variance layer, half-buffers, "
            "histograms nor min/max/spp: one plain render), where a method's output moved "
            "the frame's mean luminance by more than this fraction (its clamps took the "
            "light of rare bright samples, which the input's mean holds), scale the output "
            "by one factor to the input's mean; 1: keep the output as it is. auto has its "
            "own rule (--auto-plain-mean)",
            &CommonParams::maxMeanShift, 0, 1)};
}

// "auto", or a method of the registry; null for another name.
std::unique_ptr<api::FrontEnd> FrontEndByName(const std::string &name) {
    if (name == "auto") return std::make_unique<api::AutoFrontEnd>();
    const api::MethodEntry *entry = api::FindMethod(name);
    return entry ? entry->make() : nullptr;
}

// --demodulate: the color-like layers divided by a guide layer, and what multiplies back.
// Pixels whose guide is at or below 1e-3 x the channel mean are left as they are and keep
// their input in the output (as in the pivot method).
struct Demodulation {
    Image guide, color;
    std::vector<float> thresholds;
    std::string layer;
};

Demodulation Demodulate(api::Inputs &inputs, const api::FrontEnd &method, const Frame &frame,
                        const std::string &layer) {
    if (std::string why = method.Undemodulable(frame, layer); !why.empty())
        throw Error(fmt::format("--demodulate {}: {}", layer, why), ErrorKind::InvalidArgument);
    if (!frame.Has(layer))
        throw Error(ErrorKind::MissingLayer,
                    fmt::format("{}: --demodulate {} needs a layer the frame lacks: {}",
                                frame.path.empty() ? "the frame" : frame.path, layer,
                                io::Lacks(frame, fmt::format("no {} layer", layer), {layer})));
    Demodulation d;
    d.layer = layer;
    d.guide = inputs.Get(layer);
    d.color = inputs.Get("color");
    if (!d.guide.SameShape(d.color))
        throw Error(fmt::format("--demodulate: {} is {}x{}x{}, color {}x{}x{}", layer,
                                d.guide.width, d.guide.height, d.guide.channels, d.color.width,
                                d.color.height, d.color.channels),
                    ErrorKind::InvalidArgument);
    if (method.Name() == "rhf") inputs.Override("hist", inputs.Get("zhist"));
    d.thresholds = PivotThresholds(d.guide, 1e-3f);
    for (const std::string &name : inputs.Names()) {
        int power = name == "variance" ? 2
                    : (name == "color" || name == "min" || name == "max" || name == "direct" ||
                       name == "indirect")
                        ? 1
                        : 0;
        if (power == 0 || !inputs.Get(name).SameShape(d.color)) continue;
        Image image = inputs.Get(name);
        for (int c = 0; c < image.channels; ++c)
            for (size_t i = 0; i < image.PixelCount(); ++i) {
                float g = d.guide.Plane(c)[i];
                if (g > d.thresholds[c]) image.Plane(c)[i] /= power == 2 ? g * g : g;
            }
        inputs.Override(name, std::move(image));
    }
    return d;
}

void Remodulate(const Demodulation &d, const std::string &method, Result *result) {
    Image &image = result->image;
    for (int c = 0; c < image.channels; ++c)
        for (size_t i = 0; i < image.PixelCount(); ++i) {
            float g = d.guide.Plane(c)[i];
            image.Plane(c)[i] =
                g > d.thresholds[c] ? image.Plane(c)[i] * g : d.color.Plane(c)[i];
        }
    std::vector<std::string> lines = {
        fmt::format("demodulated: the method ran on color / {} (pixels with {} <= 1e-3 x the "
                    "channel mean keep their input), then multiplied back",
                    d.layer, d.layer)};
    if (method == "rhf")
        lines.push_back(
            "demodulated: rhf compared the frame's zhist (histograms of the samples of color / "
            "pivot)");
    result->plan.insert(result->plan.begin(), lines.begin(), lines.end());
}

// Refuse a frame that lacks what the method needs, saying what and how the renderer that
// wrote it makes it (the front end's Missing, io::Lacks). With --demodulate, Demodulate
// checks the guide's layers (rhf then reads zhist, not hist); auto explains its own.
void RefuseMissing(const api::FrontEnd &method, const Frame &frame,
                   const std::string &demodulate) {
    if (!demodulate.empty() || dynamic_cast<const api::AutoFrontEnd *>(&method)) return;
    if (std::string lacks = method.Missing(frame); !lacks.empty())
        throw Error(
            ErrorKind::MissingLayer,
            fmt::format("{}: {} needs layers the frame lacks: {}",
                        frame.path.empty() ? "the frame" : frame.path, method.Name(), lacks));
}

// Mean linear luminance (Rec. 709; one or two channels: the first), over finite pixels.
double MeanLuminance(const Image &image) {
    double sum = 0;
    size_t count = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            double v = image.channels < 3
                           ? image.At(0, y, x)
                           : 0.2126 * image.At(0, y, x) + 0.7152 * image.At(1, y, x) +
                                 0.0722 * image.At(2, y, x);
            if (std::isfinite(v)) sum += v, ++count;
        }
    return count ? sum / count : 0;
}

// The output's mean luminance over the input's (1 where the input's is not above 0).
double MeanRatio(const Image &input, const Image &output) {
    const double mean = MeanLuminance(input);
    return mean > 0 ? MeanLuminance(output) / mean : 1;
}

// auto's nfor alone on a frame without statistics: where its output's mean luminance is
// more than kMeanShift off the input's (nfor's firefly clamp took the light of a
// heavy-tailed frame), scale it by one factor to the input's mean (--auto-plain-mean gain),
// or run the combination instead, which restores the input's local means (combine).
void KeepTheMeanOfNforAlone(vk::Context &context, const api::FrontEnd &automatic,
                            const Frame &frame, bool refuseNonFinite, const RunOptions &options,
                            api::Inputs &inputs, const api::FrontEnd **method, Result *result,
                            std::vector<std::string> *plan) {
    const double ratio = MeanRatio(inputs.Get("color"), result->image);
    if (std::fabs(ratio - 1) <= kMeanShift) return;
    if (std::get<std::string>(automatic.Get("auto-plain-mean")) == "gain" && ratio > 0) {
        const float gain = float(1 / ratio);
        for (float &v : result->image.data) v *= gain;
        plan->push_back(fmt::format(
            "auto: nfor's output had {:.3f} of the frame's mean luminance (over 1% off: its "
            "firefly clamp took the light of rare bright samples), so it was scaled by {:.4f} "
            "to the input's (--auto-plain-mean gain)",
            ratio, gain));
        return;
    }
    plan->push_back(fmt::format(
        "auto: nfor's output had {:.3f} of the frame's mean luminance (over 1% off: its "
        "firefly clamp took the light of rare bright samples), so the candidates were "
        "combined instead (--auto-plain-mean combine)",
        ratio));
    *method = &automatic;
    api::Inputs again(frame, refuseNonFinite, automatic.Name());
    // Its warnings are the first run's (the same frame read alike): Run adds those.
    *result = api::RunTiled(context, automatic, again, options);
}

// A method run alone on a frame without sample statistics (no variance layer, half-buffers,
// histograms nor min/max/spp) reads the noise from the frame itself, and its clamps (nfor's
// fireflies, bayes's log domain) can take the light of a heavy-tailed frame's rare bright
// samples. The input's mean is unbiased: where the output's mean luminance is more than `shift`
// off it, scale the output back to it by one factor.
void KeepTheMean(const Frame &frame, const std::string &method, float shift, Result *result) {
    if (shift >= 1 || !frame.Has("color") ||
        !api::SampleStatistics(frame, *FrontEndByName("awr"), *FrontEndByName("rhf")).empty())
        return;
    const double ratio = MeanRatio(frame.Copy("color"), result->image);
    if (!(ratio > 0) || std::fabs(ratio - 1) <= shift) return;
    const float gain = float(1 / ratio);
    for (float &v : result->image.data) v *= gain;
    result->plan.push_back(fmt::format(
        "mean kept: {}'s output had {:.3f} of the frame's mean luminance (more than {:g} off, "
        "on a frame without sample statistics), so it was scaled by {:.4f} to the input's "
        "(--max-mean-shift)",
        method, ratio, shift, gain));
}

// Pixels the renderer left fully transparent (alpha 0: the background on Blender's Film >
// Transparent) keep the frame's colour, as the renderer wrote it: light a method spread
// into them would be added over whatever a compositor puts behind. The result's alpha
// (Result::alpha, the frame's) is written beside the colour.
void KeepTransparent(const Frame &frame, Result *result) {
    const Image &alpha = result->alpha;
    Image &image = result->image;
    if (alpha.channels != 1 || alpha.width != image.width || alpha.height != image.height ||
        !frame.Has("color"))
        return;
    std::vector<size_t> clear;
    for (size_t i = 0; i < alpha.PixelCount(); ++i)
        if (alpha.data[i] <= 0.f) clear.push_back(i);
    if (clear.empty()) return;
    Image color = frame.Copy("color");  // the caller's memory when the layer is borrowed
    if (!color.SameShape(image)) return;
    for (size_t i : clear) {
        // As the non-finite policy would have it: a refused frame never gets here.
        for (int c = 0; c < image.channels; ++c) {
            float v = color.Plane(c)[i];
            image.Plane(c)[i] = std::isfinite(v) ? v : 0.f;
        }
    }
    result->plan.push_back(
        fmt::format("alpha: {} fully transparent pixel(s) (alpha 0) keep the frame's colour",
                    clear.size()));
}

// The empty rim of a silhouette over a transparent background: the renderer's pixel filter
// gives a pixel of alpha 0 beside an edge a little of the edge's coverage, which few of its
// samples draw. Each pixel of alpha above 0 gives `share` of its output colour and of its
// alpha to each of its 4 neighbours of alpha 0 and keeps the rest: light and coverage move
// between pixels, none is added, and the colour stays premultiplied by the alpha written.
// Without `delivered` (the caller gets no alpha beside the colour) nothing moves: light in
// a pixel whose alpha, as the caller has it, is 0 would be added over its background.
void ShareRim(float share, bool delivered, Result *result) {
    Image &alpha = result->alpha;
    Image &image = result->image;
    if (share <= 0.f || alpha.channels != 1 || alpha.width != image.width ||
        alpha.height != image.height)
        return;
    const Image color = image, coverage = alpha;
    const int width = image.width, height = image.height;
    size_t takers = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // Only alpha 0 takes (a NaN alpha is no receiver, as in KeepTransparent).
            if (!(coverage.At(0, y, x) <= 0.f)) continue;
            bool took = false;
            for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
                int sx = x + dx, sy = y + dy;
                if (sx < 0 || sy < 0 || sx >= width || sy >= height) continue;
                float a = coverage.At(0, sy, sx);
                // A giver whose colour is not finite gives nothing (it has no share to give).
                bool finite = std::isfinite(a);
                for (int c = 0; c < image.channels; ++c)
                    finite = finite && std::isfinite(color.At(c, sy, sx));
                if (!(a > 0.f) || !finite) continue;
                took = true;
                if (!delivered) continue;
                for (int c = 0; c < image.channels; ++c) {
                    float given = share * color.At(c, sy, sx);
                    image.At(c, y, x) += given;
                    image.At(c, sy, sx) -= given;
                }
                float given = share * a;
                alpha.At(0, y, x) += given;
                alpha.At(0, sy, sx) -= given;
            }
            takers += took;
        }
    if (takers == 0) return;
    if (!delivered) {
        result->plan.push_back(fmt::format(
            "alpha: --alpha-rim left out: the output has no alpha channel, so the {} "
            "pixel(s) of alpha 0 beside covered ones keep the frame's colour (light moved "
            "there without its alpha would be added over the background)",
            takers));
        return;
    }
    result->rimPixels = int(takers);
    result->plan.push_back(fmt::format(
        "alpha: {} pixel(s) of alpha 0 beside covered ones took {} of the colour and of the "
        "alpha of each of their 4 neighbours of alpha above 0, which kept the rest (the "
        "pixel filter's coverage past an edge; --alpha-rim); the result's alpha is the "
        "frame's with those shares moved",
        takers, share));
}

bool SameType(const ParamValue &value, ParamType type) {
    switch (type) {
        case ParamType::Bool:
            return std::holds_alternative<bool>(value);
        case ParamType::Int:
            return std::holds_alternative<int>(value);
        case ParamType::Float:
            return std::holds_alternative<float>(value);
        case ParamType::String:
            return std::holds_alternative<std::string>(value);
    }
    return false;
}

const char *TypeName(ParamType type) {
    switch (type) {
        case ParamType::Bool:
            return "a bool";
        case ParamType::Int:
            return "an integer";
        case ParamType::Float:
            return "a number";
        case ParamType::String:
            return "a string";
    }
    return "?";
}

std::string ValueText(const ParamValue &value) {
    const std::string text = api::ParamValueText(value);
    return std::holds_alternative<std::string>(value) ? "'" + text + "'" : text;
}

}  // namespace

struct Method::Impl {
    std::unique_ptr<api::FrontEnd> frontEnd;
    CommonParams common;
    std::vector<ParamInfo> infos;  // the front end's, then the common ones

    Impl(std::unique_ptr<api::FrontEnd> frontEnd) : frontEnd(std::move(frontEnd)) {
        infos = this->frontEnd->Params();
        for (const api::ParamDef<CommonParams> &def : CommonDefs()) {
            ParamInfo info = def.info;
            info.defaultValue = def.get(CommonParams());
            infos.push_back(info);
        }
    }
    Impl(const Impl &other)
        : frontEnd(other.frontEnd->Clone()), common(other.common), infos(other.infos) {}

    const ParamInfo &Info(const std::string &name) const {
        for (const ParamInfo &info : infos)
            if (info.name == name) return info;
        throw Error(fmt::format("{} has no parameter '{}'", frontEnd->Name(), name),
                    ErrorKind::InvalidArgument);
    }
    bool IsCommon(const std::string &name) const {
        return name == "demodulate" || name == "non-finite" || name == "alpha-rim" ||
               name == "max-mean-shift";
    }
};

Method::Method(const std::string &name) {
    std::unique_ptr<api::FrontEnd> frontEnd = FrontEndByName(name);
    if (!frontEnd) {
        std::string known = "auto";
        for (const std::string &m : MethodNames()) known += ", " + m;
        throw Error(fmt::format("unknown method '{}' (methods: {})", name, known),
                    ErrorKind::InvalidArgument);
    }
    impl = std::make_unique<Impl>(std::move(frontEnd));
}

Method::~Method() = default;
Method::Method(const Method &other) : impl(std::make_unique<Impl>(*other.impl)) {}
Method &Method::operator=(const Method &other) {
    if (this != &other) impl = std::make_unique<Impl>(*other.impl);
    return *this;
}
Method::Method(Method &&) noexcept = default;
Method &Method::operator=(Method &&) noexcept = default;

const std::string &Method::Name() const {
    return impl->frontEnd->Name();
}
std::string Method::Summary() const {
    return impl->frontEnd->Summary();
}
const std::vector<ParamInfo> &Method::Params() const {
    return impl->infos;
}

bool Method::HasParam(const std::string &name) const {
    for (const ParamInfo &info : impl->infos)
        if (info.name == name) return true;
    return false;
}

void Method::Set(const std::string &name, double value) {
    const ParamInfo &info = impl->Info(name);
    if (info.type == ParamType::Int && value == std::floor(value) && std::abs(value) < 2e9)
        return Set(name, ParamValue(int(value)));
    // A whole number beyond an int is no other type's value: it is out of the range.
    if (info.type == ParamType::Int && value == std::floor(value))
        throw Error(fmt::format("{}: parameter '{}' is {:.0f}, outside [{}, {}]", Name(), name,
                                value, info.min, info.max),
                    ErrorKind::InvalidArgument);
    Set(name, ParamValue(float(value)));
}

void Method::Set(const std::string &name, ParamValue value) {
    const ParamInfo &info = impl->Info(name);
    // An integer where a number is asked for is a number.
    if (info.type == ParamType::Float && std::holds_alternative<int>(value))
        value = float(std::get<int>(value));
    if (!SameType(value, info.type))
        throw Error(fmt::format("{}: parameter '{}' takes {}, not {}", Name(), name,
                                TypeName(info.type), ValueText(value)),
                    ErrorKind::InvalidArgument);
    // Compare in the parameter's own type: 1e-6f is below the double 1e-6.
    bool outside = info.type == ParamType::Int
                       ? !(std::get<int>(value) >= info.min && std::get<int>(value) <= info.max)
                   : info.type == ParamType::Float
                       ? !(std::get<float>(value) >= float(info.min) &&
                           std::get<float>(value) <= float(info.max))
                       : false;
    if (outside)
        throw Error(fmt::format("{}: parameter '{}' is {}, outside [{}, {}]", Name(), name,
                                ValueText(value), info.min, info.max),
                    ErrorKind::InvalidArgument);
    if (info.type == ParamType::String && !info.choices.empty() &&
        std::find(info.choices.begin(), info.choices.end(), std::get<std::string>(value)) ==
            info.choices.end()) {
        throw Error(fmt::format("{}: {} takes {}, not {}", Name(), name,
                                api::OrList(info.choices), ValueText(value)),
                    ErrorKind::InvalidArgument);
    }
    if (impl->IsCommon(name)) {
        for (const api::ParamDef<CommonParams> &def : CommonDefs())
            if (def.info.name == name) def.set(impl->common, value);
        return;
    }
    impl->frontEnd->Set(name, value);
}

void Method::SetText(const std::string &name, const std::string &text) {
    const ParamInfo &info = impl->Info(name);
    try {
        size_t used = 0;
        switch (info.type) {
            case ParamType::Bool:
                if (text != "true" && text != "false" && text != "1" && text != "0")
                    throw std::invalid_argument(text);
                return Set(name, text == "true" || text == "1");
            case ParamType::Int: {
                int v = std::stoi(text, &used);
                if (used != text.size()) throw std::invalid_argument(text);
                return Set(name, v);
            }
            case ParamType::Float: {
                float v = std::stof(text, &used);
                if (used != text.size()) throw std::invalid_argument(text);
                return Set(name, v);
            }
            case ParamType::String:
                return Set(name, text);
        }
    } catch (const std::logic_error &) {
        throw Error(fmt::format("{}: parameter '{}' takes {}, not '{}'", Name(), name,
                                TypeName(info.type), text),
                    ErrorKind::InvalidArgument);
    }
}

ParamValue Method::Get(const std::string &name) const {
    impl->Info(name);
    if (impl->IsCommon(name)) {
        for (const api::ParamDef<CommonParams> &def : CommonDefs())
            if (def.info.name == name) return def.get(impl->common);
    }
    return impl->frontEnd->Get(name);
}

std::vector<std::string> Method::Uses() const {
    std::vector<std::string> layers = impl->frontEnd->Uses();
    if (layers.empty()) return {};
    layers.insert(layers.end(), {"color", "alpha"});
    // Demodulation divides by the guide; rhf then reads the histograms of color / pivot.
    if (!impl->common.demodulate.empty())
        layers.insert(layers.end(), {"pivot", "albedo", "zhist"});
    std::sort(layers.begin(), layers.end());
    layers.erase(std::unique(layers.begin(), layers.end()), layers.end());
    return layers;
}

std::string Method::Missing(const Frame &frame) const {
    // Every method denoises the colour: a frame without one runs none (said first, then what
    // else the method lacks).
    std::string lacks = impl->frontEnd->Missing(frame);
    if (frame.Has("color")) return lacks;
    return lacks.empty() ? "no color layer" : "no color layer; " + lacks;
}

Result Method::Run(Device &device, const Frame &frame, const RunOptions &options) const {
    if (options.output.data) api::CheckOutput(frame, options.output);
    vk::Context &context = api::ContextOf(device);
    api::CancelScope cancel(context, options.cancel);
    context.ResetLedger();
    auto start = std::chrono::steady_clock::now();
    const api::FrontEnd *method = impl->frontEnd.get();
    const std::string &demodulate = impl->common.demodulate;
    std::vector<std::string> autoPlan;
    Result result;
    try {
        // auto combines the methods on the frame itself; with --demodulate it picks one.
        // Without statistics it runs nfor alone (--auto-plain).
        const api::AutoFrontEnd *plainAuto = nullptr;
        if (const auto *automatic = dynamic_cast<const api::AutoFrontEnd *>(method)) {
            if (!demodulate.empty()) {
                method = &automatic->Pick(frame, demodulate, &autoPlan);
            } else if (const api::FrontEnd *nfor =
                           automatic->PickWithoutStatistics(frame, &autoPlan)) {
                method = nfor;
                plainAuto = automatic;
            }
        }
        RefuseMissing(*method, frame, demodulate);
        bool refuseNonFinite = impl->common.nonFinite == "refuse";
        api::Inputs inputs(frame, refuseNonFinite, method->Name());
        Demodulation demodulation;
        if (!demodulate.empty()) demodulation = Demodulate(inputs, *method, frame, demodulate);
        result = api::RunTiled(context, *method, inputs, options);
        if (plainAuto)
            KeepTheMeanOfNforAlone(context, *plainAuto, frame, refuseNonFinite, options, inputs,
                                   &method, &result, &autoPlan);
        if (!demodulate.empty()) Remodulate(demodulation, method->Name(), &result);
        result.warnings.insert(result.warnings.begin(), inputs.warnings.begin(),
                               inputs.warnings.end());
    } catch (const Error &) {
        cancel.ThrowIfCancelled();
        throw;
    }
    // auto leaves out a candidate that fails, a cancelled one too.
    cancel.ThrowIfCancelled();
    result.method = method->Name();
    result.plan.insert(result.plan.begin(), autoPlan.begin(), autoPlan.end());
    // auto keeps the mean by its own rule (KeepTheMeanOfNforAlone) and combination.
    if (!dynamic_cast<const api::AutoFrontEnd *>(impl->frontEnd.get()))
        KeepTheMean(frame, method->Name(), impl->common.maxMeanShift, &result);
    if (frame.Has("alpha")) result.alpha = frame.Copy("alpha");
    KeepTransparent(frame, &result);
    // The moved alpha reaches the caller in Result::alpha or in the output's last channel.
    bool alphaDelivered =
        !options.output.data || options.output.channels == result.image.channels + 1;
    ShareRim(impl->common.alphaRim, alphaDelivered, &result);
    if (options.output.data) {
        api::WriteOutput(result.image, result.alpha, options.output);
        result.image = Image();
    }
    result.wallMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
    const vk::Context::MemoryLedger &ledger = context.Ledger();
    result.peakBytes = ledger.peak;
    for (const auto &[name, bytes] : ledger.allocations)
        result.allocations.push_back({name, bytes});
    return result;
}

std::vector<Stage> Method::Reference(Device &device, const Frame &frame) const {
    const api::FrontEnd *method = impl->frontEnd.get();
    const std::string &demodulate = impl->common.demodulate;
    std::vector<std::string> ignored;
    // The reference of auto's combination is its kernels' (tests/methods/auto_test.cpp):
    // here, the one method auto picks first without a combination (nfor on a frame without
    // statistics, even where Run's mean check then combines).
    if (const auto *automatic = dynamic_cast<const api::AutoFrontEnd *>(method)) {
        const api::FrontEnd *nfor =
            demodulate.empty() ? automatic->PickWithoutStatistics(frame, &ignored) : nullptr;
        method = nfor ? nfor : &automatic->Pick(frame, demodulate, &ignored);
    }
    RefuseMissing(*method, frame, demodulate);
    api::Inputs inputs(frame, impl->common.nonFinite == "refuse", method->Name());
    if (!demodulate.empty()) Demodulate(inputs, *method, frame, demodulate);
    return method->Reference(api::ContextOf(device), inputs);
}

double Result::GpuMs() const {
    double ms = 0;
    for (const Timing &t : timings) ms += std::max(t.gpuMs, 0.0);
    return ms;
}

std::vector<std::string> MethodNames() {
    std::vector<std::string> names;
    for (const api::MethodEntry &entry : api::Registry()) names.push_back(entry.name);
    return names;
}

const char *Version() {
    return MCD_VERSION;
}

}  // namespace mcd
