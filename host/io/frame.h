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

// WritePng with an alpha channel (1 channel, the image's size; null: none) stored as the
// PNG's straight alpha: the color is written as it is, alpha linear and clamped to [0,1].
void WritePngWithAlpha(const std::string &path, const Image &image, const Image *alpha,
                       float exposure = 1.f);

}  // namespace mcd::io
