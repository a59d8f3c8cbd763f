// What the io code knows of an image file before reading its pixels, the same for an
// EXR (read with OpenEXR) and any other file (read by the OpenImageIO module, loaded at the
// first such file: host/io/oiio_module.h).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/io/oiio_module.h"

namespace mcd::io {

// How a channel's values are stored.
enum class SampleType { UInt8, UInt16, UInt32, Half, Float, Double, Other };

struct ImageHeader {
    bool exr = false;
    int x = 0, y = 0, width = 0, height = 0, depth = 1;
    // The display window (an EXR's displayWindow); the data window where the file has none.
    int fullX = 0, fullY = 0, fullWidth = 0, fullHeight = 0;
    // In OpenImageIO's order (an EXR's unprefixed channels first, R,G,B,A before others
    // within a layer), which GroupChannels' ties depend on.
    std::vector<std::string> channelNames;
    std::vector<SampleType> channelTypes;
    std::vector<std::string> typeNames;  // for messages
    bool tiled = false, deep = false;
    // A multi-part EXR: the part described (the one a frame is read from) and every part.
    int parts = 1;
    int part = 0;
    struct Part {
        std::string name;                         // "" when the file names none
        int x = 0, y = 0, width = 0, height = 0;  // the data window
        std::vector<std::string> channelNames;    // the file's order
        bool color = false;                       // its channels make a "color" layer
        bool joined = false;  // some of its channels are joined to the read part's
        std::string left;     // why it, or some of its channels, were not joined
    };
    std::vector<Part> partList;  // filled for EXRs of more than one part
    // Where each of channelNames is stored: its part and its name there. Empty when every
    // channel is the read part's under its own name.
    struct ChannelSource {
        int part = 0;
        std::string name;
    };
    std::vector<ChannelSource> channelSources;
    // The file's attributes by OpenImageIO's names ("capDate" is "DateTime", an EXR's
    // compression a string); "oiio:*" names are OpenImageIO's hints, not the file's.
    std::map<std::string, std::string> strings;
    std::map<std::string, int> ints;
    std::map<std::string, float> floats;
};

// The frame metadata keys that carry an EXR's windows from ReadFrame to WriteExr, as
// "xmin ymin xmax ymax" (OpenEXR's names: layout, never written as attributes). ReadFrame
// sets them only when the data window does not start at 0,0 or the display window differs.
inline constexpr const char *kDataWindowKey = "dataWindow";
inline constexpr const char *kDisplayWindowKey = "displayWindow";

// A window as "xmin ymin xmax ymax".
std::string WindowText(int x, int y, int width, int height);

// The window of WindowText's form; false when text is not one.
bool ParseWindow(const std::string &text, int *x, int *y, int *width, int *height);

// Set kDataWindowKey and kDisplayWindowKey in metadata for an EXR whose windows are not
// the default ones (data window at 0,0, display window the same).
void AddWindows(const ImageHeader &header, std::map<std::string, std::string> &metadata);

// Whether the file starts with OpenEXR's magic number.
bool IsExrFile(const std::string &path);

// The header of the EXR part a frame is read from: part 0 when it holds the colour (a
// "color" layer) or no part does, else the first part that does; partList lists them all.
// The channels of the other parts of the same data window are joined to it (after its own,
// channelSources saying where each is stored), an unprefixed name ("R") taking its part's
// name as its layer ("albedo.R"); a name the frame already has stays the read part's.
// Throws mcd::Error (Io) naming the path.
ImageHeader ReadExrHeader(const std::string &path);

// The header of any image file: EXR with OpenEXR, others with the module.
ImageHeader ReadImageHeader(const std::string &path);

// EXR channel names (a ChannelList's alphabetical order) in OpenImageIO's order; the
// permutation: result[k] is names[order[k]].
std::vector<int> OiioChannelOrder(const std::vector<std::string> &names);

// Whether an EXR header field is the file's layout (channels, windows, tiles, ...), not
// an attribute.
bool IsLayoutAttribute(const std::string &name);

// An attribute name as OpenImageIO calls it ("capDate" -> "DateTime"), and back.
std::string OiioAttributeName(const std::string &exrName);
std::string ExrAttributeName(const std::string &oiioName);

// A non-EXR file opened through the module: its header and its rows as float.
class ModuleImage {
  public:
    explicit ModuleImage(const std::string &path);
    ~ModuleImage();
    ModuleImage(const ModuleImage &) = delete;
    ModuleImage &operator=(const ModuleImage &) = delete;

    const ImageHeader &Header() const { return header; }
    // Rows [y0, y1) of the data window, every channel interleaved; integer types
    // normalized to [0,1]. Throws mcd::Error (Io).
    void ReadRows(int y0, int y1, float *pixels);

  private:
    void FillHeader(const McdOiioHeader *h);

    std::string path;
    const McdOiioApi *api = nullptr;
    void *handle = nullptr;
    ImageHeader header;
};

// Write 8-bit pixels to path in format ("png") through the module. Throws mcd::Error (Io)
// naming `target` (the file the caller writes; path may be its temporary).
void WriteModuleUInt8(const std::string &path, const std::string &target, const char *format,
                      int width, int height, int channels, const unsigned char *pixels,
                      bool unassociatedAlpha);

// Whether this process has loaded the OpenImageIO module.
bool IoModuleLoaded();

// The module, loaded at the first call: from the directory MCD_OIIO_MODULE_DIR names if
// set, else beside the binary or library holding this code, else in ../lib from there (the
// tool in <prefix>/bin), else the configured install's lib directory. Throws mcd::Error (Io)
// naming `path` and `what` needs it when it is missing.
const McdOiioApi &IoModule(const std::string &path, const std::string &what);

}  // namespace mcd::io
