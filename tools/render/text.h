// Lettering for the built-in scenes' textures ("ABC", "FRONT"): a word rasterised with
// stb_truetype from a Debian font, as a 1-channel coverage image.
#pragma once

#include <string>

#include "host/image.h"

namespace mcd::render {

// Throws mcd::Error naming the font file when it is missing (Debian: fonts-dejavu-core).
Image TextBitmap(const std::string &text, int pixelHeight);

}  // namespace mcd::render
