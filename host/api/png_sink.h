// The one file the core library still writes: auto's map of the largest weights
// (--auto-map), until the command line writes it from the run's result (issue #28). The
// core has no image writer; libmcdenoise_io installs its WritePng here when it is loaded.
#pragma once

#include <string>

#include "mcdenoise/image.h"

namespace mcd::api {

using PngWriter = void (*)(const std::string &path, const Image &image, float exposure);

// Called by the I/O library as it loads.
void SetPngWriter(PngWriter writer);

// Write `image` as a PNG through the installed writer; throws mcd::Error (I/O) naming the
// path when no writer is installed (a program linked with the core library only).
void WritePngThroughIo(const std::string &path, const Image &image);

}  // namespace mcd::api
