#include "host/methods/staged_run.h"

#include <iterator>

#include "host/vk/gpu_image.h"

namespace mcd {

StagedRun::StagedRun(vk::Context &context, bool keepStages)
    : context(context), recorder(context), keepStages(keepStages) {}

void StagedRun::Submit() {
    recorder.Submit();
    timings.insert(timings.end(), recorder.Timings().begin(), recorder.Timings().end());
}

void StagedRun::Stage(std::string name, const vk::GpuImage &buffer) {
    Stage(std::move(name), [&buffer] { return buffer.Download(); });
}

void StagedRun::Stage(std::string name, const std::function<Image()> &download) {
    if (!keepStages) return;
    Submit();
    stages.emplace_back(std::move(name), download());
}

void StagedRun::StageAtEnd(std::string name, const vk::GpuImage &buffer) {
    if (!keepStages) return;
    atEnd.emplace_back(stages.size(), &buffer);
    stages.emplace_back(std::move(name), Image());
}

void StagedRun::AddStage(std::string name, Image image) {
    if (keepStages) stages.emplace_back(std::move(name), std::move(image));
}

void StagedRun::Finish(MethodResult &result) {
    Submit();
    for (const auto &[index, buffer] : atEnd) stages[index].second = buffer->Download();
    atEnd.clear();
    auto append = [](auto &to, auto &from) {
        to.insert(to.end(), std::make_move_iterator(from.begin()),
                  std::make_move_iterator(from.end()));
        from.clear();
    };
    append(result.plan, plan);
    append(result.warnings, warnings);
    append(result.timings, timings);
    append(result.stages, stages);
}

}  // namespace mcd
