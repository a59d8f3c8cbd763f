/* The interface of libmcdenoise_oiio, the module that reads and writes the image files
 * OpenEXR does not (PNG, HDR, PFM, TIFF, ...) with OpenImageIO. The io code loads it with
 * dlopen the first time such a file comes, so that a process reading and writing EXR only
 * never maps OpenImageIO and its hundreds of libraries. Plain C: no OpenImageIO type (nor
 * any C++ one) crosses it. */
#pragma once

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bumped whenever a field below changes; the loader refuses a module of another version. */
#define MCD_OIIO_MODULE_VERSION 1
/* The one symbol the module exports. */
#define MCD_OIIO_MODULE_ENTRY "McdOiioModule"

typedef enum McdOiioAttributeKind {
    MCD_OIIO_STRING = 0,
    MCD_OIIO_INT = 1,
    MCD_OIIO_FLOAT = 2,
} McdOiioAttributeKind;

/* A file attribute by OpenImageIO's name ("oiio:ColorSpace" included). */
typedef struct McdOiioAttribute {
    const char *name;
    McdOiioAttributeKind kind;
    const char *text;
    int integer;
    float real;
} McdOiioAttribute;

/* Subimage 0 of an opened file; the strings live as long as the handle. Channel types
 * are "uint8", "uint16", "uint32", "half", "float", "double" or another type's name. */
typedef struct McdOiioHeader {
    const char *formatName;
    int x, y, width, height, depth, channelCount;
    int tiled, deep, subimages;
    const char *const *channelNames;
    const char *const *channelTypes;
    int attributeCount;
    const McdOiioAttribute *attributes;
} McdOiioHeader;

typedef struct McdOiioApi {
    int version;
    /* Open a file for reading (colour as stored: unassociated alpha is not applied); null
     * with a message in error on failure. */
    void *(*open)(const char *path, const McdOiioHeader **header, char *error,
                  size_t errorSize);
    /* Rows [y0, y1) of the data window, every channel, interleaved float (integer types
     * normalized to [0,1]). Zero with a message on failure. */
    int (*readRows)(void *image, int y0, int y1, float *pixels, char *error, size_t errorSize);
    void (*close)(void *image);
    /* Write 8-bit sRGB pixels (1-4 channels, interleaved) in the format named ("png");
     * unassociatedAlpha: the colour is not divided by alpha. Zero with a message on failure. */
    int (*writeUInt8)(const char *path, const char *format, int width, int height, int channels,
                      const unsigned char *pixels, int unassociatedAlpha, char *error,
                      size_t errorSize);
} McdOiioApi;

typedef const McdOiioApi *(*McdOiioModuleFunction)(void);

#ifdef __cplusplus
}
#endif
