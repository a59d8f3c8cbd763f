/* mcdenoise's C API for files (libmcdenoise_io, over libmcdenoise's mcdenoise_c.h): a
 * frame read from an image file (EXR, PFM, HDR, PNG, ...: what OpenImageIO reads) into
 * named layers, and layers written as a float32 EXR. Errors as in mcdenoise_c.h. */
#ifndef MCDENOISE_IO_C_H
#define MCDENOISE_IO_C_H

#include "mcdenoise/mcdenoise_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Read part 0 of an image file into a frame that owns its layers. `layers` (NULL: every
 * layer) lists the `layerCount` layer names to read. NULL on failure (MCD_ERROR_IO for a
 * file that cannot be read). */
MCDFrame mcdReadFrame(const char *path, const char *const *layers, int layerCount);

/* Write `count` layers, each from a view of the caller's memory (all of one size), as a
 * float32 EXR (zip), atomically: the file at `path` is either the old one or the new. */
bool mcdWriteExr(const char *path, const char *const *names, const MCDView *views, int count);

#ifdef __cplusplus
}
#endif

#endif /* MCDENOISE_IO_C_H */
