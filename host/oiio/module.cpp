// libmcdenoise_oiio: the image files OpenEXR does not read, through OpenImageIO, behind the
// plain C interface of host/io/oiio_module.h.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "host/io/oiio_module.h"

namespace {

void SetError(char *error, size_t errorSize, const std::string &message) {
    if (!error || errorSize == 0) return;
    size_t n = std::min(errorSize - 1, message.size());
    std::memcpy(error, message.data(), n);
    error[n] = 0;
}

// Run `body`; a C++ exception becomes the error text and `failed`, so none crosses the C
// interface.
template <typename Result, typename Body>
Result Guarded(char *error, size_t errorSize, Result failed, Body body) {
    try {
        return body();
    } catch (const std::exception &e) {
        SetError(error, errorSize, e.what());
    } catch (...) {
        SetError(error, errorSize, "unknown exception");
    }
    return failed;
}

const char *TypeName(OIIO::TypeDesc type) {
    if (type == OIIO::TypeDesc::UINT8) return "uint8";
    if (type == OIIO::TypeDesc::UINT16) return "uint16";
    if (type == OIIO::TypeDesc::UINT32) return "uint32";
    if (type == OIIO::TypeDesc::HALF) return "half";
    if (type == OIIO::TypeDesc::FLOAT) return "float";
    if (type == OIIO::TypeDesc::DOUBLE) return "double";
    return nullptr;
}

// An open file with its header in the interface's terms; the strings are owned here.
struct Image {
    std::unique_ptr<OIIO::ImageInput> in;
    std::string formatName;
    std::vector<std::string> names, types, attributeNames, attributeTexts;
    std::vector<const char *> namePointers, typePointers;
    std::vector<McdOiioAttribute> attributes;
    McdOiioHeader header{};
    std::vector<float> whole;  // a tiled file's pixels, read at the first request
};

void FillHeader(Image &image) {
    const OIIO::ImageSpec &spec = image.in->spec();
    image.formatName = image.in->format_name();
    for (int c = 0; c < spec.nchannels; ++c) {
        image.names.push_back(spec.channelnames[c]);
        const char *name = TypeName(spec.channelformat(c));
        image.types.push_back(name ? name : spec.channelformat(c).c_str());
    }
    for (const OIIO::ParamValue &attribute : spec.extra_attribs) {
        OIIO::TypeDesc type = attribute.type();
        if (type != OIIO::TypeString && type != OIIO::TypeInt && type != OIIO::TypeFloat)
            continue;
        image.attributeNames.push_back(attribute.name().string());
        image.attributeTexts.push_back(type == OIIO::TypeString ? attribute.get_string() : "");
        McdOiioAttribute a{};
        a.kind = type == OIIO::TypeString ? MCD_OIIO_STRING
                 : type == OIIO::TypeInt  ? MCD_OIIO_INT
                                          : MCD_OIIO_FLOAT;
        if (type == OIIO::TypeInt) a.integer = attribute.get_int();
        if (type == OIIO::TypeFloat) a.real = attribute.get_float();
        image.attributes.push_back(a);
    }
    // Pointers last: the vectors above no longer grow.
    for (size_t k = 0; k < image.attributes.size(); ++k) {
        image.attributes[k].name = image.attributeNames[k].c_str();
        image.attributes[k].text = image.attributeTexts[k].c_str();
    }
    for (size_t c = 0; c < image.names.size(); ++c) {
        image.namePointers.push_back(image.names[c].c_str());
        image.typePointers.push_back(image.types[c].c_str());
    }
    McdOiioHeader &h = image.header;
    h.formatName = image.formatName.c_str();
    h.x = spec.x, h.y = spec.y, h.width = spec.width, h.height = spec.height;
    h.depth = spec.depth, h.channelCount = spec.nchannels;
    h.tiled = spec.tile_width > 0, h.deep = spec.deep;
    h.subimages = spec.get_int_attribute("oiio:subimages", 1);
    h.channelNames = image.namePointers.data();
    h.channelTypes = image.typePointers.data();
    h.attributeCount = int(image.attributes.size());
    h.attributes = image.attributes.data();
}

void *OpenImage(const char *path, const McdOiioHeader **header, char *error, size_t errorSize) {
    // Keep colour as stored: OIIO would premultiply a PNG's unassociated alpha.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto image = std::make_unique<Image>();
    image->in = OIIO::ImageInput::open(path, &config);
    if (!image->in) {
        SetError(error, errorSize, OIIO::geterror());
        return nullptr;
    }
    FillHeader(*image);
    *header = &image->header;
    return image.release();
}

void *Open(const char *path, const McdOiioHeader **header, char *error, size_t errorSize) {
    return Guarded<void *>(error, errorSize, nullptr,
                           [&] { return OpenImage(path, header, error, errorSize); });
}

int ReadImageRows(void *handle, int y0, int y1, float *pixels, char *error, size_t errorSize) {
    Image &image = *static_cast<Image *>(handle);
    const OIIO::ImageSpec &spec = image.in->spec();
    bool ok = true;
    if (spec.tile_width > 0) {
        // Tiles come in tile rows only: the whole image once, rows handed out from it.
        if (image.whole.empty()) {
            image.whole.resize(size_t(spec.width) * spec.height * spec.nchannels);
            ok = image.in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeFloat,
                                      image.whole.data());
            // A failed read leaves nothing behind: a retry reads again, not the remains.
            if (!ok) std::vector<float>().swap(image.whole);
        }
        size_t row = size_t(spec.width) * spec.nchannels;
        if (ok)
            std::copy(image.whole.begin() + ptrdiff_t(row * y0),
                      image.whole.begin() + ptrdiff_t(row * y1), pixels);
    } else {
        ok = image.in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                      OIIO::TypeFloat, pixels);
    }
    if (!ok) SetError(error, errorSize, image.in->geterror());
    return ok;
}

int ReadRows(void *handle, int y0, int y1, float *pixels, char *error, size_t errorSize) {
    return Guarded(error, errorSize, 0,
                   [&] { return ReadImageRows(handle, y0, y1, pixels, error, errorSize); });
}

void Close(void *handle) {
    delete static_cast<Image *>(handle);
}

// Write `bytes` to `path`, every failure (open, write, flush, close) an error return.
int WriteBytes(const char *path, const std::vector<unsigned char> &bytes, char *error,
               size_t errorSize) {
    std::FILE *file = std::fopen(path, "wb");
    if (!file) {
        SetError(error, errorSize, std::strerror(errno));
        return 0;
    }
    bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size() &&
                   std::fflush(file) == 0;
    int writeErrno = errno;
    if (std::fclose(file) != 0 && written) {
        written = false;
        writeErrno = errno;
    }
    if (!written) SetError(error, errorSize, std::strerror(writeErrno));
    return written ? 1 : 0;
}

int WriteImageUInt8(const char *path, const char *format, int width, int height, int channels,
                    const unsigned char *pixels, int unassociatedAlpha, char *error,
                    size_t errorSize) {
    // Encode into memory and write the bytes here: the format's own file writes leave a
    // failed write (a full disk) unreported, and the caller would rename a cut-off file over
    // a good one. The memory outlives the writer, which may still write to it as it closes.
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput memory(bytes);
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(format);
    if (!out) {
        SetError(error, errorSize, OIIO::geterror());
        return 0;
    }
    OIIO::ImageSpec spec(width, height, channels, OIIO::TypeUInt8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    if (unassociatedAlpha) spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->supports("ioproxy") || !out->set_ioproxy(&memory)) {
        SetError(error, errorSize, std::string(format) + " cannot be encoded into memory");
        return 0;
    }
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeUInt8, pixels) || !out->close()) {
        SetError(error, errorSize, out->geterror());
        return 0;
    }
    return WriteBytes(path, bytes, error, errorSize);
}

int WriteUInt8(const char *path, const char *format, int width, int height, int channels,
               const unsigned char *pixels, int unassociatedAlpha, char *error,
               size_t errorSize) {
    return Guarded(error, errorSize, 0, [&] {
        return WriteImageUInt8(path, format, width, height, channels, pixels, unassociatedAlpha,
                               error, errorSize);
    });
}

const McdOiioApi kApi = {MCD_OIIO_MODULE_VERSION, Open, ReadRows, Close, WriteUInt8};

}  // namespace

extern "C" __attribute__((visibility("default"))) const McdOiioApi *McdOiioModule(void) {
    return &kApi;
}
