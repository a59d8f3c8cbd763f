// Accumulation (issue #16): N renders of one view, independent seeds and equal spp each,
// become one frame with the layers the methods read (ARCHITECTURE.md's layer table): the
// mean, the variance of the mean from the spread of the frames, spp, min/max, RHF
// histograms of the frame means, the auxiliary layers and the half-buffers half0/half1.
// One frame at a time: memory does not grow with the number of frames.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/common/samples.h"
#include "host/io/frame.h"

namespace mcd::io {

// A file's size, layers (our names, channel counts) and string metadata, read without its
// pixels: enough to refuse a mismatched input before any heavy work.
struct FrameHeader {
    std::string path;
    int width = 0, height = 0;
    std::map<std::string, int> layers;
    std::map<std::string, std::string> metadata;
};
FrameHeader ReadFrameHeader(const std::string &path);

// Throws mcd::Error naming `other`'s file when its size or layers differ from `first`'s.
void CheckSameLayout(const FrameHeader &first, const FrameHeader &other);

// The samples per pixel a frame's metadata states (host/common/samples.h).
using mcd::SppFromMetadata;

// RHF Algorithm 1 with the authors' constants, the rule tools/render uses for each sample:
// add a value of weight 1 to a pixel's 3 x bins histogram (colour c's bins at c * bins).
void AddToRhfHistogram(const double color[3], int bins, float *histogram);

// The layers Accumulator::Add reads (for ReadOptions::layers); the others are made anew
// (variance, hist) or not carried.
std::vector<std::string> AccumulatorReads();

// Whether the accumulated frame holds a layer of the inputs by this name: averaged, taken
// from the first frame or made anew. The others are "not carried".
bool AccumulatorKeeps(const std::string &layer);

// Whether the frames traced the same camera rays. Blender Cycles sends a pixel's sample 0
// through the pixel's centre whatever the seed, so N 1-spp frames with other seeds share
// every camera ray: their first hits (albedo, normal, depth) are the same bits, and their
// mean converges to the point-sampled (aliased) image, not the pixel-filtered one.
enum class CameraRays {
    Unknown,   // one frame, or colors that differ and no albedo, normal or depth to compare
    Distinct,  // an albedo, normal or depth value differs between frames: the rays differ
    Shared,    // albedo, normal and depth (those present) the same bits in every frame,
               // the color not: the same rays with other seeds
    Identical  // color (and albedo, normal, depth when present) the same bits in every
               // frame: one render repeated, not other seeds
};

struct AccumulateOptions {
    int histBins = 20;  // per channel: the hist layer has 3 * histBins + 1 channels
    // Also half0's own layers ("half0.<layer>" for io::Half0Layers(): the same statistics
    // over the frames half0.color is the mean of), so that auto's runs on half0 read no
    // layer that half1's samples moved. Doubles the accumulator's memory.
    bool half0Layers = true;
};

class Accumulator {
  public:
    explicit Accumulator(AccumulateOptions options = {});

    // Adds one frame. The first fixes the size and the layers; a later frame whose size or
    // layers differ is refused (mcd::Error naming its path) and leaves the sums as they
    // were. Non-finite values are left out of the statistics and counted per layer.
    void Add(const Frame &frame);

    // The accumulated frame: color, variance, spp, min, max, hist, half0.color,
    // half1.color, and the carried layers (means over frames; objectId and partId from the
    // first frame; direct.variance and indirect.variance, the variances of the direct and
    // indirect means, beside direct and indirect); with half0Layers and three frames or more,
    // half0.<layer> for each of those that io::Half0Layers() names, as Finish of an
    // Accumulator given the even frames (0, 2, ...) alone. Throws when no frame was added.
    Frame Finish();

    int Frames() const { return frames; }
    // Per layer, the pixels whose value was left out of its statistics for being NaN/Inf.
    const std::map<std::string, uint64_t> &NonFinite() const { return nonFinite; }
    // Layers of the inputs that the result neither carries nor makes anew (partials,
    // zhist, a reference, ...).
    const std::vector<std::string> &Dropped() const { return dropped; }
    // Whether the frames share their camera rays, from bitwise comparison of every frame's
    // color, albedo, normal and depth with the first frame's (a NaN equals a NaN of the
    // same bits; +0 and -0 differ: one ray gives one bit pattern).
    CameraRays SharedCameraRays() const;
    // The layers of albedo, normal, depth that the frames have (those compared).
    const std::vector<std::string> &RayLayers() const { return rayLayers; }

  private:
    // A layer averaged over the frames, with its own per-pixel count of finite values and,
    // for direct and indirect, the sum of squared deviations from the running mean.
    struct MeanLayer {
        std::vector<double> sum;
        std::vector<uint32_t> count;
        int channels = 0;
        std::vector<double> m2;  // empty: no variance
    };
    void Start(const Frame &frame);
    void AddMean(MeanLayer &layer, const std::string &name, const Image &image);
    void CompareWithFirst(const Frame &frame);

    AccumulateOptions options;
    std::string firstPath;
    int width = 0, height = 0, frames = 0;
    std::map<std::string, int> layout;  // the first frame's layers and channel counts
    // color: running mean and sum of squared deviations (Welford), per channel.
    std::vector<double> mean, m2, spp;
    std::vector<uint32_t> count;
    std::vector<float> lo, hi;
    Image hist;
    MeanLayer halves[2];
    std::unique_ptr<Accumulator> half0;  // the even frames alone (half0Layers)
    std::map<std::string, MeanLayer> means;
    std::map<std::string, Image> firstOf;  // ids: the first frame's
    std::map<std::string, uint64_t> nonFinite;
    std::vector<std::string> dropped;
    // The first frame's color and geometry layers while they may still equal every later
    // frame's (constant memory; freed once a geometry layer differs, color once it does).
    std::map<std::string, Image> firstRays;
    std::vector<std::string> rayLayers;
    bool geometryDiffers = false, colorDiffers = false;
};

}  // namespace mcd::io
