// Frames on disk (libmcdenoise_io, target mcdenoise::io): reading any file OpenImageIO
// reads into a frame of named layers, and writing EXR and PNG. EXR goes through OpenEXR;
// other formats through the module libmcdenoise_oiio.so (OpenImageIO), loaded at the
// first such file from beside this library, else the install's lib directory. The core library
// (mcdenoise/mcdenoise.h) has no file-format dependency; programs that read or write
// files link this one too.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mcdenoise/frame.h"
#include "mcdenoise/image.h"

namespace mcd {

// What ReadFrame reads. `layers` lists our layer names (partial images by their full names,
// or "partial*" for all of them); empty reads every layer. A layer a renderer's convention
// composes (Cycles' direct and indirect from its light passes, pbrt-v4's and Mitsuba's
// variance) brings the passes it is made of. Other layers are neither read nor stored.
struct ReadOptions {
    std::vector<std::string> layers;
    // Bytes the read layers may take; 0: the machine's physical memory. A header that
    // claims more (a damaged or hostile file) is an error, not an allocation.
    uint64_t memoryLimit = 0;
};

// Read an image file (of a multi-part EXR the part that holds the colour, else part 0, with
// the other parts of its data window joined: docs/frames.md), all channels as float,
// grouped into layers (owned). 8- and 16-bit data (PNG, ...) is sRGB-decoded to linear;
// 32-bit unsigned EXR channels (ids) keep their integer values. Throws mcd::Error naming the
// path on any failure.
Frame ReadFrame(const std::string &path, const ReadOptions &options = {});

// ReadFrame(path).Get(layer).
Image ReadImage(const std::string &path, const std::string &layer = "color");

// Write float32 EXR (zip) with the layers in the given order; ReadFrame gives back the same
// layers bit for bit. All layers must have the same size. The metadata keys dataWindow and
// displayWindow (ReadFrame sets them for an EXR whose windows are not the default ones) place
// the layers where their frame was; windows of another size than the layers' are not theirs
// and are left out (data and display window at 0,0, the layers' size). Atomic: the file at
// path is either the old one or the new one.
void WriteExr(const std::string &path,
              const std::vector<std::pair<std::string, const Image *>> &layers,
              const std::map<std::string, std::string> &metadata = {});

// Write an 8-bit sRGB preview of a 1- or 3-channel image: values times exposure, clamped
// to [0,1]; pixels with NaN or Inf in any channel are magenta. Atomic, as WriteExr.
void WritePng(const std::string &path, const Image &image, float exposure = 1.f);

}  // namespace mcd
