// How a pipeline runs, apart from what it computes (the method's parameters,
// host/params/<method>.h): one struct for every pipeline, each reading the fields it has a
// use for. None of them changes the output image.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace mcd {

class RunMemo;

struct RunSetup {
    // Download every stage's buffer (for `mcdenoise diff`): one submission per stage, and
    // stages a run fuses otherwise (awr's shrinkage) as passes of their own.
    bool keepStages = false;
    // Called after each strip of a long stage (stage, rows done, rows), pivot's fit and
    // gather.
    std::function<void(const std::string &stage, int done, int total)> progress;

    // A tile of a larger frame (host/api/tiled_run.h): the window's origin in its whole
    // frame and the frame's size (0: the image is the frame). rhf's recombination maps
    // through the frame's sizes, which differ from the window's by more than a factor 2^s.
    int frameX0 = 0, frameY0 = 0, frameWidth = 0, frameHeight = 0;
    // A tile's frame-wide quantities, taken from the whole frame so that the tile computes
    // what the untiled run computes there (0 and empty: from the image itself): rhf's scales
    // filtered and its histograms' count-preserving rescale at each scale s >= 1
    // (histScales[s]).
    int scalesUsed = 0;
    std::vector<float> histScales;
    // bayes --zeros restore: the frame's zeros already judged by CheckBayesZeros (on the whole
    // frame), so that a tile or a probe does not refuse or pass on its own part.
    bool zerosDecided = false;

    // Splitting knobs: the same result in smaller pieces (0: automatic, from the device's
    // binding limit). Tests set them to run the split paths on small frames.
    int planesPerSlot = 0;     // rhf: histogram planes per buffer
    int stripRows = 0;         // rhf: centre rows per distance strip
    int swtGroupChannels = 0;  // bayes --bayes-transform swt: channels per transform
    // pivot planefit: its fit and gather run in row strips of about this many centres, one
    // submission each (0: one strip).
    int stripPixels = 1 << 16;

    // Work shared with other runs on the same frame (host/methods/run_memo.h): taken from
    // it where an earlier run left it, left in it for later runs. nullptr: none.
    RunMemo *memo = nullptr;
    // rhf: the histograms' identity in the memo's keys where the caller knows it (a frame's
    // layer: api::Inputs::LayerId); empty: hashed from the values.
    std::string histId;
};

}  // namespace mcd
