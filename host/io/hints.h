// What the user of the renderer that wrote a frame does to get a layer the frame lacks:
// the pass to enable in Blender, the film or integrator of pbrt-v4 and Mitsuba 3, our
// renderer's --layers, or `mcdenoise accumulate` for sample statistics. One table, read by
// the methods' front ends (host/api/method_*.cpp) when they say what a frame is missing;
// header-only, so that the library's core, which reads no file, needs no file I/O for it.
#pragma once

#include <algorithm>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "host/io/conventions.h"
#include "mcdenoise/frame.h"

namespace mcd::io {

// The renderer a frame came from, as its conventions (conventions.h) and our renderer's
// metadata tell; Unknown when neither does (an accumulated frame, a hand-made one).
enum class Renderer { Ours, Blender, Pbrt, Mitsuba, Unknown };

namespace hints {

// One row: the layers a renderer's user gets one way. Rows are searched in order: the
// frame's renderer first, then Unknown's rows, which hold for any renderer.
struct Hint {
    Renderer renderer;
    std::initializer_list<std::string_view> layers;
    std::string_view text;
};

// clang-format off
inline const Hint kHints[] = {
    {Renderer::Ours, {"variance", "min", "max", "spp"},
     "`mcdenoise render` writes it with every frame; or combine N renders with `mcdenoise "
     "accumulate`"},
    {Renderer::Ours, {"hist"},
     "render with `mcdenoise render --layers hist`, or combine N renders with `mcdenoise "
     "accumulate`"},
    {Renderer::Ours, {"half0.color", "half1.color"},
     "render with `mcdenoise render --layers halves`, or combine N renders with `mcdenoise "
     "accumulate`"},
    {Renderer::Ours, {"direct", "indirect", "direct.variance", "indirect.variance"},
     "render with `mcdenoise render --layers split`"},
    {Renderer::Ours, {"pivot"}, "render with `mcdenoise render --layers pivot`"},
    {Renderer::Ours, {"albedo", "normal", "depth", "objectId", "partId"},
     "render with `mcdenoise render --layers gbuffer`"},
    {Renderer::Ours, {"zhist"}, "render with `mcdenoise render --layers zhist`"},

    // Cycles' pivot stand-in is its albedo: both rows say the same, so it is said once.
    {Renderer::Blender, {"albedo", "normal", "depth", "pivot"},
     "in Blender, enable View Layer Properties > Passes > Data > Denoising Data (Denoising "
     "Albedo, Normal and Depth; the pivot method uses the albedo)"},
    {Renderer::Blender, {"objectId", "partId"},
     "in Blender, enable View Layer Properties > Passes > Data > Indexes: Object Index and "
     "Material Index"},
    {Renderer::Blender, {"direct", "indirect"},
     "in Blender, enable View Layer Properties > Passes > Light: Diffuse, Glossy and "
     "Transmission (Direct, Indirect and Color), Emission and Environment"},
    {Renderer::Blender, {"variance", "min", "max", "spp", "hist", "half0.color",
                         "half1.color", "direct.variance", "indirect.variance"},
     "Blender Cycles writes no sample statistics: render the frame N times with different "
     "seeds and the camera jittered by a sub-pixel offset each time, and combine them with "
     "`mcdenoise accumulate` (docs/frames.md)"},

    {Renderer::Pbrt, {"albedo", "normal", "pivot", "variance"},
     "render with pbrt-v4's gbuffer film (Film \"gbuffer\": Albedo, N and Variance, with "
     "samplesPerPixel in the header; the pivot method uses the albedo)"},
    {Renderer::Pbrt, {"min", "max", "spp", "hist", "half0.color", "half1.color"},
     "pbrt-v4 writes no such sample statistics: render the frame N times with different "
     "seeds and combine them with `mcdenoise accumulate` (docs/frames.md)"},

    {Renderer::Mitsuba, {"albedo", "normal", "depth", "objectId", "pivot"},
     "wrap Mitsuba 3's integrator in the aov integrator (aovs "
     "\"albedo:albedo,sh_normal:sh_normal,depth:depth,shape_index:shape_index\"; the pivot "
     "method uses the albedo)"},
    {Renderer::Mitsuba, {"variance"},
     "wrap Mitsuba 3's integrator in the moment integrator and add a header attribute spp; "
     "or render the frame N times with different seeds and combine them with `mcdenoise "
     "accumulate` (docs/frames.md)"},
    {Renderer::Mitsuba, {"min", "max", "spp", "hist", "half0.color", "half1.color"},
     "Mitsuba 3 writes no such sample statistics: render the frame N times with different "
     "seeds and combine them with `mcdenoise accumulate` (docs/frames.md)"},

    // Any renderer.
    {Renderer::Unknown, {"zhist"},
     "only `mcdenoise render --layers zhist` writes histograms of color / pivot"},
    {Renderer::Unknown, {"variance", "min", "max", "spp", "hist", "half0.color",
                         "half1.color", "direct.variance", "indirect.variance"},
     "render the frame N times with different seeds and combine them with `mcdenoise "
     "accumulate` (docs/frames.md)"},
    {Renderer::Unknown, {"albedo", "normal", "depth", "pivot", "objectId", "partId"},
     "write the renderer's albedo, normal and depth outputs under the names docs/frames.md "
     "lists (the pivot method uses the albedo)"},
};
// clang-format on

}  // namespace hints

// The renderer a frame came from: its mcd:convention line, else our renderer's mcd:renderer.
inline Renderer RendererOf(const Frame &frame) {
    if (auto it = frame.metadata.find(kConventionKey); it != frame.metadata.end()) {
        const std::string &line = it->second;
        if (line.find("read as Blender Cycles") != std::string::npos) return Renderer::Blender;
        if (line.find("read as pbrt-v4") != std::string::npos) return Renderer::Pbrt;
        if (line.find("read as Mitsuba 3") != std::string::npos) return Renderer::Mitsuba;
    }
    if (auto it = frame.metadata.find("mcd:renderer");
        it != frame.metadata.end() && it->second.starts_with("mcdenoise"))
        return Renderer::Ours;
    return Renderer::Unknown;
}

// How to get `layer` from the renderer that wrote `frame`; "" when the table has no row.
inline std::string HowToGet(const Frame &frame, const std::string &layer) {
    Renderer renderer = RendererOf(frame);
    for (Renderer pass : {renderer, Renderer::Unknown})
        for (const hints::Hint &hint : hints::kHints)
            if (hint.renderer == pass &&
                std::find(hint.layers.begin(), hint.layers.end(), layer) != hint.layers.end())
                return std::string(hint.text);
    return "";
}

// `what` (e.g. "no variance layer") followed by how to get `layers` from the frame's
// renderer, each distinct hint once: what a front end's Missing() returns.
inline std::string Lacks(const Frame &frame, const std::string &what,
                         const std::vector<std::string> &layers) {
    std::vector<std::string> texts;
    for (const std::string &layer : layers)
        if (std::string hint = HowToGet(frame, layer);
            !hint.empty() && std::find(texts.begin(), texts.end(), hint) == texts.end())
            texts.push_back(hint);
    std::string text = what;
    for (size_t i = 0; i < texts.size(); ++i) text += (i ? "; " : " (") + texts[i];
    return texts.empty() ? text : text + ")";
}

}  // namespace mcd::io
