// The frames of one `mcdenoise denoise`, denoised on one device: the pipelines built by the
// first frame and kept, the next frame read while this one runs and the last one written.
// One frame given as a file is a sequence of one: the same run, explanation, warnings and
// write, with its failure the command's own and no sequence summary.
#pragma once

#include <vector>

#include "mcdenoise/mcdenoise.h"
#include "mcdenoise/temporal.h"
#include "tools/mcdenoise/sequence.h"

namespace mcd::tool {

struct DenoiseSettings {
    bool explain = false;  // print what ran, what was left out, buffers and pipelines
    // One frame named as a file: a failure ends the command at once, naming no frame
    // number, and no summary follows; its warnings do not repeat the file name.
    bool single = false;
    // --overwrite-input onto the input itself: the result replaces the renderer's colour,
    // every other channel is copied from the file, the noisy one added
    // (io::WriteDenoisedOver).
    bool inPlace = false;
    mcd::DeviceOptions device;
    // A sequence's temporal mode (docs/sequences.md): each frame gathered with the frames
    // whose numbers lie within the radius of its own before the method runs; null, or a
    // frame with no such neighbour, runs the frame alone.
    const Temporal *temporal = nullptr;
};

// Denoise `frames` with `method`. A sequence's frame that fails is reported and the others
// go on; the command fails at the end when any did.
void DenoiseFrames(const std::vector<SequenceFrame> &frames, const Method &method,
                   const DenoiseSettings &settings);

}  // namespace mcd::tool
