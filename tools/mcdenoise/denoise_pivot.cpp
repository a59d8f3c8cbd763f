// `mcdenoise denoise --method pivot`: Ershov et al.'s pivot-image filter
// (host/methods/pivot.h), planefit or the bilateral baseline.
#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <memory>

#include "cpu_reference/pivot_filter.h"
#include "host/error.h"
#include "host/methods/pivot.h"
#include "tools/mcdenoise/denoise_method.h"

namespace mcd::tool {
namespace {

struct PivotCliOptions {
    std::string filter = "planefit", guides = "auto", noise = "auto";
    bool noPartials = false;
    PivotOptions options;
};

// The method's inputs and options from the frame and the command line.
PivotInputs PivotInputsOf(const PivotCliOptions &opt, const io::Frame &frame,
                          PivotOptions *options) {
    *options = opt.options;
    if (opt.filter == "planefit")
        options->filter = PivotFilter::PlaneFit;
    else if (opt.filter == "bilateral")
        options->filter = PivotFilter::Bilateral;
    else
        throw Error("--filter takes planefit or bilateral, not '" + opt.filter + "'");
    if (opt.guides != "auto" && opt.guides != "none")
        throw Error("--guides takes auto or none, not '" + opt.guides + "'");
    if (opt.noise != "auto" && opt.noise != "estimate")
        throw Error("--pivot-noise takes auto or estimate, not '" + opt.noise + "'");
    if (!frame.Has("pivot"))
        throw Error(fmt::format(
            "{}: the pivot method needs a pivot layer (render it with `mcdenoise render "
            "--layers pivot`)",
            frame.path));
    PivotInputs in;
    in.color = &frame.Get("color");
    in.pivot = &frame.Get("pivot");
    if (opt.noise == "auto" && frame.Has("variance")) in.variance = &frame.Get("variance");
    if (opt.guides == "auto") {
        if (frame.Has("normal")) in.normal = &frame.Get("normal");
        if (frame.Has("objectId")) in.objectId = &frame.Get("objectId");
        if (frame.Has("partId")) in.partId = &frame.Get("partId");
    }
    // Section 8: partial0, partial1, ... while the frame has them, and the remainder.
    if (!opt.noPartials) {
        for (int k = 0; frame.Has(fmt::format("partial{}.color", k)); ++k) {
            std::string name = fmt::format("partial{}", k);
            if (!frame.Has(name + ".pivot"))
                throw Error(
                    fmt::format("{}: layer {}.color has no {}.pivot (or pass "
                                "--no-partials)",
                                frame.path, name, name));
            PivotPartial partial{&frame.Get(name + ".color"), &frame.Get(name + ".pivot")};
            if (opt.noise == "auto" && frame.Has(name + ".variance"))
                partial.variance = &frame.Get(name + ".variance");
            in.partials.push_back(partial);
        }
        if (!in.partials.empty()) {
            if (!frame.Has("remainder"))
                throw Error(fmt::format(
                    "{}: the partial images need a remainder layer (or pass --no-partials)",
                    frame.path));
            in.remainder = &frame.Get("remainder");
        }
    }
    return in;
}

}  // namespace

DenoiseMethod PivotMethod() {
    auto opt = std::make_shared<PivotCliOptions>();
    DenoiseMethod method;
    method.name = "pivot";
    method.summary =
        "Ershov et al.'s pivot-image filter (needs a pivot layer; normals, objectId, partId, "
        "variance refine it)";
    method.addOptions = [opt](CLI::App *cmd) {
        PivotOptions &o = opt->options;
        cmd->add_option("--filter", opt->filter,
                        "pivot: planefit (the paper's plane fits, eqs. 10-13) or bilateral "
                        "(cross-bilateral baseline of z = color / pivot)")
            ->capture_default_str();
        cmd->add_option("--max-radius", o.maxRadius,
                        "pivot: largest half-size of a planefit square (paper: 30-40)")
            ->capture_default_str()
            ->check(CLI::Range(2, 64));
        cmd->add_option("--target-noise", o.targetNoise,
                        "pivot: relative std of a centre's fit that stops the growth")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e6f));
        cmd->add_option("--good-noise", o.goodNoise,
                        "pivot: pixels whose relative std exceeds this are left out of fits")
            ->capture_default_str()
            ->check(CLI::Range(1e-6f, 1e6f));
        cmd->add_option("--disagreement", o.disagreement,
                        "pivot: relative square-vs-quadrant difference that stops the growth")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e6f));
        cmd->add_option("--robust-k", o.k,
                        "pivot: k of eq. 10; above 0 the fits down-weight outliers, which "
                        "lowers the error but darkens heavy-tailed frames (relief-abc 16 spp: "
                        "mean 0.65 of the reference with 0.3, 1.04 with 0)")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e6f));
        cmd->add_option(
               "--sigma-weight", o.sigmaWeight,
               "pivot: weight of the noise term sigma in eq. 10 (1: the paper; 0 keeps "
               "fireflies' energy in heavy-tailed noise)")
            ->capture_default_str()
            ->check(CLI::Range(0.f, 1e6f));
        cmd->add_option("--bilateral-radius", o.bilateralRadius,
                        "pivot: window half-size of the bilateral filter")
            ->capture_default_str()
            ->check(CLI::Range(0, 64));
        cmd->add_option("--sigma-range", o.sigmaRange,
                        "pivot: bilateral range sigma on the pivot's relative difference")
            ->capture_default_str()
            ->check(CLI::Range(1e-6f, 1e6f));
        cmd->add_option("--pivot-floor", o.floor,
                        "pivot: pixels with pivot <= this x the channel mean keep their input")
            ->capture_default_str()
            ->check(CLI::Range(1e-12f, 1e6f));
        cmd->add_option("--guides", opt->guides,
                        "pivot: auto (normals and ids when the frame has them) or none")
            ->capture_default_str();
        cmd->add_option("--pivot-noise", opt->noise,
                        "pivot: auto (the variance layer when present) or estimate (from the "
                        "3x3 neighbours of z)")
            ->capture_default_str();
        cmd->add_flag("--no-partials", opt->noPartials,
                      "pivot: filter color as one image even when the frame has section 8's "
                      "partial<k>.color/.pivot and remainder layers (by default each partial "
                      "is filtered against its own pivot and the remainder added)");
    };
    method.missing = [](const io::Frame &frame) -> std::string {
        return frame.Has("pivot") ? "" : "no pivot layer";
    };
    method.run = [opt](vk::Context &context, const io::Frame &frame) {
        PivotOptions options;
        PivotInputs in = PivotInputsOf(*opt, frame, &options);
        // Planefit takes seconds to minutes on a CPU device: show how far it is on a
        // terminal (the line is overwritten, then ended).
        bool terminal = isatty(fileno(stderr)) && options.filter == PivotFilter::PlaneFit;
        if (terminal)
            options.progress = [](const std::string &stage, int done, int total) {
                std::fprintf(stderr, "\rpivot: %-6s %3d%%", stage.c_str(), 100 * done / total);
            };
        PivotResult pivot = PivotDenoise(context, in, options);
        if (terminal) std::fprintf(stderr, "\n");
        DenoiseResult result;
        result.image = std::move(pivot.image);
        result.plan = std::move(pivot.plan);
        result.timings = std::move(pivot.timings);
        return result;
    };
    method.stages = [opt](vk::Context &context, const io::Frame &frame) {
        PivotOptions options;
        PivotInputs in = PivotInputsOf(*opt, frame, &options);
        // The stages of the single-image pipeline (the partials run the same one).
        in.partials.clear();
        in.remainder = nullptr;
        options.keepStages = true;
        PivotResult gpu = PivotDenoise(context, in, options);
        // The CPU reference on the same inputs and options.
        ref::PivotParams p;
        p.floor = options.floor;
        p.maxRadius = options.maxRadius;
        p.targetNoise = options.targetNoise;
        p.goodNoise = options.goodNoise;
        p.disagreement = options.disagreement;
        p.k = options.k;
        p.sigmaWeight = options.sigmaWeight;
        p.bilateralRadius = options.bilateralRadius;
        p.sigmaRange = options.sigmaRange;
        Image ids;
        if (in.objectId || in.partId) {
            ids = Image(frame.width, frame.height, 2);
            for (size_t i = 0; i < ids.PixelCount(); ++i) {
                if (in.objectId) ids.data[i] = in.objectId->data[i];
                if (in.partId) ids.data[ids.PixelCount() + i] = in.partId->data[i];
            }
        }
        ref::PivotGuides guides{in.normal, ids.Empty() ? nullptr : &ids};
        ref::PivotRatio ratio =
            ref::PivotRatioOf(*in.color, *in.pivot, in.variance, p.floor, guides.ids);
        std::vector<Image> cpu = {ratio.z, ratio.nu};
        if (options.filter == PivotFilter::PlaneFit) {
            cpu.push_back(ref::PivotFit(ratio, guides, p));
            cpu.push_back(ref::PivotGather(*in.color, *in.pivot, ratio, cpu.back(), guides));
        } else {
            cpu.push_back(ref::PivotBilateral(*in.color, *in.pivot, ratio, guides, p));
        }
        std::vector<StagePair> pairs;
        for (size_t i = 0; i < gpu.stages.size(); ++i)
            pairs.push_back({gpu.stages[i].first, std::move(gpu.stages[i].second), cpu[i]});
        return pairs;
    };
    return method;
}

}  // namespace mcd::tool
