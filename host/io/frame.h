// Frames on disk: the public frame type and its readers and writers
// (include/mcdenoise/frame.h), under the names the internal code has always used.
// Layer names follow the README's layer table; see layer_names.h.
#pragma once

#include "mcdenoise/frame.h"

namespace mcd::io {

using mcd::Frame;
using mcd::ReadFrame;
using mcd::ReadImage;
using mcd::WriteExr;
using mcd::WritePng;

}  // namespace mcd::io
