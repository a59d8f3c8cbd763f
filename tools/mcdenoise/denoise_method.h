// The methods of `mcdenoise denoise`, one file each (denoise_<name>.cpp). A method adds
// its own options to the command and turns a frame into a denoised image; the command
// reads the frame, checks paths, times the run, measures error and writes the result.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

#include "host/image.h"
#include "host/io/frame.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"

namespace mcd::tool {

// What a method run gives back.
struct DenoiseResult {
    Image image;
    std::vector<std::string> plan;            // stages run and left out, and why (--explain)
    std::vector<std::string> warnings;        // printed always, e.g. counts of NaN pixels
    std::vector<vk::DispatchTiming> timings;  // per dispatch, GPU
};

// One stage of a method, as the GPU computed it and as the CPU reference does.
struct StagePair {
    std::string name;
    Image gpu, cpu;
};

struct DenoiseMethod {
    std::string name;
    std::string summary;  // one line for --help
    // Register the method's options on the denoise command; help texts start "name: ".
    std::function<void(CLI::App *)> addOptions;
    // Validate the options and run; throws mcd::Error naming what is wrong and where.
    std::function<DenoiseResult(vk::Context &, const io::Frame &)> run;
    // Why the frame cannot be denoised by this method with its current options ("" when
    // it can): `--method auto` skips such methods. Empty: the method needs only color.
    std::function<std::string(const io::Frame &)> missing;
    // Every stage on the GPU and on the CPU reference, same options (`mcdenoise diff`).
    std::function<std::vector<StagePair>(vk::Context &, const io::Frame &)> stages;
};

DenoiseMethod AwrMethod();
DenoiseMethod BayesMethod();
DenoiseMethod RhfMethod();

// Every method the tool knows, in the order --help lists them.
inline std::vector<DenoiseMethod> DenoiseMethods() {
    return {AwrMethod(), BayesMethod(), RhfMethod()};
}

}  // namespace mcd::tool
