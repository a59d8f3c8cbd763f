#include "tools/render/text.h"

#include <fmt/format.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "host/error.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#define STB_TRUETYPE_IMPLEMENTATION
#define STBTT_STATIC
#include <stb/stb_truetype.h>
#pragma GCC diagnostic pop

namespace mcd::render {

Image TextBitmap(const std::string &text, int pixelHeight) {
    const char *path = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";
    std::ifstream file(path, std::ios::binary);
    if (!file)
        throw Error(fmt::format("font {} not found (Debian package fonts-dejavu-core)", path),
                    ErrorKind::Io);
    std::vector<unsigned char> data((std::istreambuf_iterator<char>(file)), {});
    stbtt_fontinfo font;
    if (!stbtt_InitFont(&font, data.data(), stbtt_GetFontOffsetForIndex(data.data(), 0)))
        throw Error(fmt::format("cannot read font {}", path), ErrorKind::Io);
    float scale = stbtt_ScaleForPixelHeight(&font, float(pixelHeight));
    int ascent, descent, gap;
    stbtt_GetFontVMetrics(&font, &ascent, &descent, &gap);
    int baseline = int(ascent * scale), height = int((ascent - descent) * scale) + 1;
    // A margin of a quarter of the height around the word keeps repeated tiles apart.
    int margin = pixelHeight / 4, width = 2 * margin;
    for (char c : text) {
        int advance, bearing;
        stbtt_GetCodepointHMetrics(&font, c, &advance, &bearing);
        width += int(advance * scale) + 1;
    }
    int fullHeight = height + 2 * margin;
    std::vector<unsigned char> pixels(size_t(width) * fullHeight, 0);
    int x = margin;
    for (char c : text) {
        int advance, bearing, x0, y0, x1, y1;
        stbtt_GetCodepointHMetrics(&font, c, &advance, &bearing);
        stbtt_GetCodepointBitmapBox(&font, c, scale, scale, &x0, &y0, &x1, &y1);
        int at = (margin + baseline + y0) * width + x + x0;
        stbtt_MakeCodepointBitmap(&font, pixels.data() + at, x1 - x0, y1 - y0, width, scale,
                                  scale, c);
        x += int(advance * scale) + 1;
    }
    Image image(width, fullHeight, 1);
    for (size_t i = 0; i < pixels.size(); ++i) image.data[i] = pixels[i] / 255.f;
    return image;
}

}  // namespace mcd::render
