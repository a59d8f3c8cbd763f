#include "host/api/registry.h"

#include <algorithm>
#include <cstdlib>
#include <variant>

namespace mcd::api {

// The front ends, one per method (method_<name>.cpp).
std::unique_ptr<FrontEnd> AwrFrontEnd();
std::unique_ptr<FrontEnd> BayesFrontEnd();
std::unique_ptr<FrontEnd> NforFrontEnd();
std::unique_ptr<FrontEnd> PivotFrontEnd();
std::unique_ptr<FrontEnd> RhfFrontEnd();

namespace {

// nfor's probe: the widest of the run's first-pass bandwidths alone, over windows 2 pixels
// narrower, a noisy frame's too (the pilot's pass as the run's). The run picks among its
// bandwidths per pixel by SURE, mostly the widest; on the accumulated frames this probe weighed
// the candidates as well as a probe of the run's own settings did, and as probes over windows
// 1 or 0 pixels narrower did, for less work (docs/methods/auto.md, nfor.md).
void NforCheaperProbe(FrontEnd &nfor) {
    const std::string list = std::get<std::string>(nfor.Get("bandwidths"));
    std::string widest;
    float most = 0;
    size_t begin = 0;
    while (begin <= list.size()) {
        size_t end = std::min(list.find(',', begin), list.size());
        std::string item = list.substr(begin, end - begin);
        char *rest = nullptr;
        float k = std::strtof(item.c_str(), &rest);
        // A list the run refuses is left for the run to name.
        if (item.empty() || *rest != '\0') return;
        if (k > most) most = k, widest = item;
        begin = end + 1;
    }
    if (!widest.empty()) nfor.Set("bandwidths", widest);
    nfor.Set("radius", std::max(std::get<int>(nfor.Get("radius")) - 2, 1));
    nfor.Set("noisy-radius", std::max(std::get<int>(nfor.Get("noisy-radius")) - 2, 0));
}

// The pivot filter reads its guides from the normals and the object and part ids.
const std::vector<std::string> kGuideLayers = {"normal", "objectId", "partId"};

std::vector<MethodEntry> Build() {
    // Pick order, as before the combination: the geometric mean over the built-in scenes
    // of the error at equal time (awr, rhf, bayes, pivot).
    // Run order: the measured strongest first, the variants after every method's own
    // parameters. The pivot variants without the guides ("no ids": --guides none) filter
    // the pixels next to another object or part id, which pivot keeps as they are: on
    // Blender Cycles frames, whose walls and objects each have an id, those pixels carried
    // most of pivot's error (README). "bayes no split" runs where bayes runs split.
    // Where the half-buffers weigh the candidates (an accumulated frame), nfor runs, and
    // the variants that did not earn their time beside it there do not; where SURE on a
    // variance layer does, the pivot variants without robust weights (k0) did not earn
    // theirs either: they run on the frame's own estimate, where they are what lifts
    // interior's plain frames. awr runs only where named (byDefault false): small shares
    // everywhere for much time. docs/methods/auto.md has the measurements.
    constexpr unsigned kNotHalves = AutoVariant::kVariance | AutoVariant::kOwn;
    const ParamValue none = std::string("none");
    return {
        {"awr",
         AwrFrontEnd,
         0,
         {{"awr", {}, 5, {0.8f, 0.1f, 0.9f}, "magenta", {}, kNotHalves, nullptr, false}}},
        {"bayes",
         BayesFrontEnd,
         2,
         {{"bayes", {}, 4, {1.f, 0.8f, 0.05f}, "yellow", {}, kNotHalves},
          {"bayes no split",
           {{"no-split", true}},
           9,
           {0.5f, 0.25f, 0.1f},
           "brown",
           {},
           kNotHalves}}},
        // nfor with its noise from the frame itself: the variance layer of a few accumulated
        // samples is noisy and heavy-tailed. Weighed by SURE it cost quality on our own
        // scenes, so it runs where the halves weigh it. Without statistics auto runs it
        // alone (PickWithoutStatistics). Its plain-frame passes (weak emitters, specks,
        // lights' spread, clamp's light) run as on a plain frame, since its clamp reads the
        // same estimate. "nfor layer", nfor's own setting (its weights on the variance
        // layer), runs beside it where the frame has a layer and --auto-candidates names it:
        // the two err in different places (a bright path's variance against the estimate's
        // median), but the second run's gain did not earn its time by default. It runs
        // last, so the other candidates' order and sums stay.
        {"nfor",
         NforFrontEnd,
         -1,
         {{"nfor",
           {{"nfor-noise", std::string("estimate")}},
           0,
           {0.6f, 0.2f, 1.f},
           "purple",
           {},
           AutoVariant::kHalves,
           NforCheaperProbe},
          {"nfor layer",
           {},
           10,
           {1.f, 0.6f, 0.8f},
           "pink",
           {"variance"},
           AutoVariant::kHalves,
           NforCheaperProbe,
           false}}},
        // pivot's candidates without its input-range bound (docs/methods/pivot.md, ninth
        // round).
        {"pivot",
         PivotFrontEnd,
         3,
         {{"pivot", {}, 2, {0.1f, 0.7f, 0.1f}, "green"},
          {"pivot k0",
           {{"robust-k", 0.f}},
           3,
           {0.1f, 0.3f, 1.f},
           "blue",
           {},
           AutoVariant::kOwn},
          {"pivot no ids", {{"guides", none}}, 7, {1.f, 0.5f, 0.f}, "orange", kGuideLayers},
          {"pivot k0 no ids",
           {{"robust-k", 0.f}, {"guides", none}},
           8,
           {0.5f, 0.5f, 0.5f},
           "grey",
           kGuideLayers,
           AutoVariant::kOwn}},
         {{"pivot-range", 0}, {"pivot-fit-clusters", true}, {"pivot-edge", 0.f}},
         "with the range, held near their input where the fits overshoot, or with a mirror's "
         "lights kept at their input, they drew the weights to pivot where its error is the "
         "input's; with the shading-edge test auto measured worse on low-sample frames of "
         "scenes with textures the pivot does not show"},
        {"rhf",
         RhfFrontEnd,
         1,
         {{"rhf", {}, 1, {0.9f, 0.1f, 0.1f}, "red"},
          {"rhf 2 scales", {{"nscales", 2}}, 6, {0.1f, 0.9f, 0.9f}, "cyan"}}},
    };
}

}  // namespace

const std::vector<MethodEntry> &Registry() {
    static const std::vector<MethodEntry> entries = Build();
    return entries;
}

const MethodEntry *FindMethod(const std::string &name) {
    for (const MethodEntry &entry : Registry())
        if (entry.name == name) return &entry;
    return nullptr;
}

std::vector<RegisteredVariant> AutoVariants() {
    std::vector<RegisteredVariant> variants;
    for (const MethodEntry &entry : Registry())
        for (const AutoVariant &variant : entry.variants)
            variants.push_back({&entry, &variant});
    std::stable_sort(variants.begin(), variants.end(), [](const auto &a, const auto &b) {
        return a.variant->order < b.variant->order;
    });
    return variants;
}

std::vector<const MethodEntry *> PickOrder() {
    std::vector<const MethodEntry *> order;
    for (const MethodEntry &entry : Registry())
        if (entry.pick >= 0) order.push_back(&entry);
    std::stable_sort(order.begin(), order.end(),
                     [](const auto *a, const auto *b) { return a->pick < b->pick; });
    return order;
}

}  // namespace mcd::api
