// What every method's run shares: the command recorder, the GPU times of every dispatch
// across its submissions, the stages kept for `mcdenoise diff`, the `--explain` plan and
// the warnings; and MethodResult, the one result they end up in.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "host/image.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"

namespace mcd {

namespace vk {
struct GpuImage;
}  // namespace vk

// A method's output and what it says about the run. A method with more to say derives
// (BayesResult, RhfResult, PivotResult).
struct MethodResult {
    Image image;
    std::vector<std::string> plan;            // what ran and what was left out, and why
    std::vector<std::string> warnings;        // what the input held that was not taken as is
    std::vector<vk::DispatchTiming> timings;  // per dispatch, GPU, in submission order
    // With keepStages: intermediate images by name, in order (each method's header lists
    // its names; `mcdenoise diff` pairs them with the CPU reference's stages).
    std::vector<std::pair<std::string, Image>> stages;
};

// One run of a method's dispatches. Without keepStages the stage calls do nothing, so a
// pipeline records straight through into as few submissions as it asks for.
class StagedRun {
  public:
    StagedRun(vk::Context &context, bool keepStages);
    StagedRun(const StagedRun &) = delete;
    StagedRun &operator=(const StagedRun &) = delete;

    vk::Context &Context() { return context; }
    vk::Recorder &Recorder() { return recorder; }
    bool KeepsStages() const { return keepStages; }

    // Submit what is recorded, wait, and keep its dispatches' timings.
    void Submit();

    // With keepStages: submit, download `buffer` and keep it as stage `name`.
    void Stage(std::string name, const vk::GpuImage &buffer);
    // With keepStages: submit, then keep what `download` returns (a buffer read back and
    // laid out as an image) as stage `name`.
    void Stage(std::string name, const std::function<Image()> &download);
    // With keepStages: keep `buffer` as stage `name`, downloaded by Finish after the last
    // submission (no submission here): for buffers nothing recorded later writes.
    void StageAtEnd(std::string name, const vk::GpuImage &buffer);
    // With keepStages: keep `image`, made on the host, as stage `name`.
    void AddStage(std::string name, Image image);

    void Plan(std::string line) { plan.push_back(std::move(line)); }
    void Warn(std::string line) { warnings.push_back(std::move(line)); }
    // The timings so far (for plan lines that report them, or helpers that append).
    std::vector<vk::DispatchTiming> &Timings() { return timings; }

    // Submit what is left, download the stages kept for the end and append plan, warnings,
    // timings and stages to `result`'s (its image is the caller's). Ends the run.
    void Finish(MethodResult &result);

  private:
    vk::Context &context;
    vk::Recorder recorder;
    bool keepStages;
    std::vector<std::string> plan, warnings;
    std::vector<vk::DispatchTiming> timings;
    std::vector<std::pair<std::string, Image>> stages;
    // Stages whose download waits for Finish: index into stages, and the buffer.
    std::vector<std::pair<size_t, const vk::GpuImage *>> atEnd;
};

}  // namespace mcd
