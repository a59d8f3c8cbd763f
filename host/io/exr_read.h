// Reading the channels of an EXR that a frame needs, straight into float planes. Scanline
// files stored without compression or with ZIP/ZIPS (ours, pbrt-v4's, Blender's default)
// are decoded here, chunks in parallel, only the bytes of the channels asked for put back
// together; others go through OpenEXR's own reader (Imf::InputFile).
#pragma once

#include <string>
#include <vector>

namespace mcd::io {

// Where one EXR channel's values go: a plane of the data window's size, row after row.
struct ExrTarget {
    std::string channel;
    float *plane = nullptr;
};

enum class ExrDecoder {
    Auto,     // ours where it can, else OpenEXR's
    OpenExr,  // always OpenEXR's (the tests' reference)
};

// Read part `part` of the EXR at path into the targets as float (half widened, 32-bit
// unsigned converted as OpenEXR does; parts after the first always by OpenEXR's reader).
// The data window must be x, y, width, height. False, with nothing read, when the file has
// subsampled channels (the caller reads it otherwise). Throws mcd::Error naming the path for
// a damaged file or a channel it does not have.
bool ReadExrChannels(const std::string &path, int x, int y, int width, int height,
                     const std::vector<ExrTarget> &targets,
                     ExrDecoder decoder = ExrDecoder::Auto, int part = 0);

struct ImageHeader;

// Read the channels of a frame's header (ReadExrHeader's) into the targets, each target named
// as the header names its channel: the read part's through ReadExrChannels, a joined part's
// from that part under its own name there (ImageHeader::channelSources). False as
// ReadExrChannels.
bool ReadExrFrameChannels(const std::string &path, const ImageHeader &header,
                          const std::vector<ExrTarget> &targets,
                          ExrDecoder decoder = ExrDecoder::Auto);

}  // namespace mcd::io
