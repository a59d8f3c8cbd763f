// nfor's kept pixels smoothed (beyond the papers): a pixel whose colour distance to every
// neighbour is far beyond its noise (a partly covered silhouette pixel against an empty
// background, its coverage drawn by few samples) weighs only itself in every window and
// comes out of the fits as it came in. It takes the mean of the output around it weighted
// by the features the fits weigh by: along a silhouette its neighbours of like albedo,
// normal and depth share its coverage noise out.
#pragma once

#include <vector>

#include "host/image.h"

namespace mcd {

// Whether the fits left the pixel (x, y) of `output` as it was in `input`: not an emitter
// (mask 1), some channel of the input above 1e-4, every channel within 1e-3 |input| + 1e-6
// of the input (both finite: unmoved), and some pixel within r (clipped) not an emitter and
// moved (a frame the fits reproduce, noise-free and first order in the columns, is left).
bool NforKeptPixel(const Image &input, const Image &output, const Image &mask, int r, int x,
                   int y);

// Which pixels the pass smooths, and over what.
struct NforKeptSettings {
    int radius = 2;  // 0: nothing
    // > 0: emitters (mask 0) whose largest albedo channel is below this (a light's partly
    // covered edge, a moving light's streak: their colour and albedo share the coverage's
    // noise) are smoothed too, without the albedo's planes in their weights; 0: every
    // emitter left.
    float weakEmitterAlbedo = 0;
    const Image *albedo = nullptr;  // the frame's (for weak emitters)
    int albedoPlanes = 0;           // the features' first planes that are the albedo
    bool keptPixels = true;  // false: only the weak emitters change (kept pixels still unread)
    // > 0: a weak emitter on a bright line (a glossy highlight's streak: along an axis or a
    // diagonal, on both sides within 2 steps a pixel whose channels' positive parts sum to
    // at least this x its own) weighs each pixel of its mean also by its brightness against
    // its own, exp(-ln((b_q + 0.01) / (b_p + 0.01))^2 / (2 lineRange^2)), b the channels'
    // positive parts' mean: it averages along its streak, not with the darker ground beside
    // it (a streak one or two pixels wide lost half its light); 0: off.
    float lineRatio = 0;
    float lineRange = 0.4f;
};

// Whether the weak emitter (x, y) lies on a bright line of `output` as lineRatio reads one.
bool NforWeakEmitterOnLine(const Image &output, float ratio, int x, int y);

// Each kept pixel of `output` (unless !keptPixels) and each weak emitter replaced by the mean
// of the output over the window of radius r clipped to the image with weights exp(-|d|^2 / (2
// (r / 2)^2)
// - sum_j (s_j (F_q,j - F_p,j))^2) (features F and weights s as the fits', the albedo's
// planes left out at a weak emitter; on a bright line, lineRatio's brightness term too), the
// other kept pixels (their input: a firefly would spread), emitters other than weak ones and
// non-finite values left out of the mean; the pixel itself has weight 1. The outputs read are
// those before any replacement. Returns how many pixels changed.
size_t NforSmoothKept(const Image &input, const Image &features,
                      const std::vector<float> &featureWeights, const Image &mask,
                      const NforKeptSettings &settings, Image *output);

}  // namespace mcd
