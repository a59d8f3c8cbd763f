#include "host/api/front_end.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "host/common/samples.h"

namespace mcd::api {

RunSetup SetupFor(const Inputs &inputs, const RunOptions &run) {
    RunSetup setup;
    setup.keepStages = run.keepStages;
    setup.progress = run.progress;
    setup.frameX0 = inputs.OriginX();
    setup.frameY0 = inputs.OriginY();
    setup.frameWidth = inputs.FrameWidth();
    setup.frameHeight = inputs.FrameHeight();
    setup.memo = inputs.Memo();
    return setup;
}

Result ResultOf(MethodResult &&run) {
    Result result;
    result.image = std::move(run.image);
    result.plan = std::move(run.plan);
    result.warnings = std::move(run.warnings);
    for (const vk::DispatchTiming &t : run.timings)
        result.timings.push_back({t.label, t.gpuMs});
    for (auto &[name, image] : run.stages) result.stages.push_back({name, std::move(image)});
    return result;
}

std::string OrList(const std::vector<std::string> &words) {
    std::string list;
    for (size_t i = 0; i < words.size(); ++i)
        list += (i == 0                  ? ""
                 : i + 1 == words.size() ? " or "
                                         : ", ") +
                (words[i].empty() ? "''" : words[i]);
    return list;
}

std::string ParamValueText(const ParamValue &value) {
    if (const bool *b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    if (const int *i = std::get_if<int>(&value)) return std::to_string(*i);
    if (const float *f = std::get_if<float>(&value)) return fmt::format("{}", *f);
    return std::get<std::string>(value);
}

int FrameSamplesPerPixel(Inputs &inputs) {
    if (!inputs.Has("spp")) return SppFromMetadata(inputs.Source().metadata);
    std::vector<float> spp;
    for (float v : inputs.Get("spp").data)
        if (std::isfinite(v)) spp.push_back(v);
    if (spp.empty()) return 0;
    auto middle = spp.begin() + long(spp.size() / 2);
    std::nth_element(spp.begin(), middle, spp.end());
    return *middle >= 1 ? int(std::lround(*middle)) : 0;
}

}  // namespace mcd::api
