// Frames on disk: the public frame type and its readers and writers
// (include/mcdenoise/io.h), under the names the internal code has always used.
// Layer names follow the README's layer table; see layer_names.h.
#pragma once

#include "mcdenoise/io.h"

namespace mcd::io {

using mcd::Frame;
using mcd::ReadFrame;
using mcd::ReadImage;
using mcd::WriteExr;
using mcd::WritePng;

// The layer that keeps the noisy colour of a frame whose colour WriteDenoisedOver
// replaced, in our names (ARCHITECTURE.md's layer table); Blender frames use Cycles' own.
inline constexpr const char *kNoisyColorLayer = "color.noisy";

// The frame's name for the colour channels of such a file once it is read: they hold the
// denoised result, and kNoisyColorLayer is read as the frame's colour.
inline constexpr const char *kDenoisedColorLayer = "color.denoised";

// Write a denoised colour into the EXR frame at `path` in place of the renderer's colour
// (denoise --overwrite-input). Every channel of the file stays under its own name, in its
// own pixel type, alpha included; the denoised colour goes where the renderer's colour was
// (Blender: <view layer>.Combined) and only the noisy colour is added: Blender frames get
// <view layer>.Noisy Image.R,G,B(,A), the pass Cycles writes when its own denoiser has
// replaced Combined, other frames kNoisyColorLayer. A file that has its noisy colour
// already (a second run, or Cycles' denoiser) keeps it. The header's attributes stay,
// `metadata` set over them (a lossy compression becomes zip). Read and written a band of rows
// at a time; atomic, as WriteExr. Throws mcd::Error for a file that is not a one-part EXR with
// a colour of `denoised`'s size.
void WriteDenoisedOver(const std::string &path, const Image &denoised,
                       const std::map<std::string, std::string> &metadata);

// WritePng with an alpha channel (1 channel, the image's size; null: none) stored as the
// PNG's straight alpha: the color is written as it is, alpha linear and clamped to [0,1].
void WritePngWithAlpha(const std::string &path, const Image &image, const Image *alpha,
                       float exposure = 1.f);

}  // namespace mcd::io
