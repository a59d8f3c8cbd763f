// The frames of one `mcdenoise denoise`, denoised on one device: the pipelines built by the
// first frame and kept, the next frame read while this one runs and the last one written.
// One frame given as a file is a sequence of one: the same run, explanation, warnings and
// write, with its failure the command's own and no sequence summary.
#pragma once

#include <vector>

#include "mcdenoise/mcdenoise.h"
#include "tools/mcdenoise/sequence.h"

namespace mcd::tool {

struct DenoiseSettings {
    bool explain = false;  // print what ran, what was left out, buffers and pipelines
    // One frame named as a file: a failure ends the command at once, naming no frame
    // number, and no summary follows; its warnings do not repeat the file name.
    bool single = false;
    // --overwrite-input onto the input itself: every layer is read and written back, the
    // noisy color kept as kNoisyColorLayer.
    bool inPlace = false;
    mcd::DeviceOptions device;
};

// Denoise `frames` with `method`. A sequence's frame that fails is reported and the others
// go on; the command fails at the end when any did.
void DenoiseFrames(const std::vector<SequenceFrame> &frames, const Method &method,
                   const DenoiseSettings &settings);

}  // namespace mcd::tool
