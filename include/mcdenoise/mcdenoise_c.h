/* mcdenoise's C API (libmcdenoise), for C and for other languages' foreign-function
 * interfaces (the Python module is ctypes over it). The C++ API is mcdenoise/mcdenoise.h;
 * files are read and written by libmcdenoise_io (mcdenoise/io_c.h).
 *
 *     MCDDevice device = mcdNewDevice(NULL);
 *     MCDFrame frame = mcdNewFrame();
 *     MCDView color = mcdInterleaved(rgb, MCD_FORMAT_FLOAT, width, height, 3);
 *     mcdSetFrameLayer(frame, "color", &color);          // borrowed, not copied
 *     MCDMethod method = mcdNewMethod("auto");
 *     mcdSetMethodFloat(method, "kappa", 0.6);
 *     MCDView out = mcdInterleaved(output, MCD_FORMAT_FLOAT, width, height, 3);
 *     MCDResult result = mcdRunMethod(method, device, frame, &out);
 *     const char *message;
 *     if (mcdGetError(&message) != MCD_ERROR_NONE) fprintf(stderr, "%s\n", message);
 *     mcdReleaseResult(result); ...
 *
 * Errors: a call that fails returns NULL, 0 or false and records its error for the calling
 * thread; mcdGetError returns it (and the message) and clears it. Every handle may be NULL
 * in a release call. Strings returned stay valid until the handle they came from is
 * released (or, for mcdGetError, until the thread's next call into the library). */
#ifndef MCDENOISE_C_H
#define MCDENOISE_C_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The kinds of mcd::ErrorKind, one to one, and none. */
typedef enum MCDError {
    MCD_ERROR_NONE = 0,
    MCD_ERROR_INVALID_ARGUMENT = 1,
    MCD_ERROR_MISSING_LAYER = 2,
    MCD_ERROR_NON_FINITE_INPUT = 3,
    MCD_ERROR_OUT_OF_MEMORY = 4,
    MCD_ERROR_DEVICE = 5,
    MCD_ERROR_IO = 6,
    MCD_ERROR_INTERNAL = 7,
    MCD_ERROR_CANCELLED = 8
} MCDError;

typedef enum MCDFormat { MCD_FORMAT_FLOAT = 1, MCD_FORMAT_HALF = 2 } MCDFormat;

/* An image in the caller's memory: element (x, y, c) at byte
 * data + y * rowByteStride + x * pixelByteStride + c * channelByteStride. Strides may be
 * negative; 0 takes the packed value (channels adjacent: an interleaved pixel; a row of
 * pixels). mcdInterleaved and mcdPlanar fill one in. */
typedef struct MCDView {
    void *data;
    MCDFormat format;
    int width, height, channels;
    int64_t pixelByteStride, rowByteStride, channelByteStride;
} MCDView;

typedef struct MCDDeviceImpl *MCDDevice;
typedef struct MCDFrameImpl *MCDFrame;
typedef struct MCDMethodImpl *MCDMethod;
typedef struct MCDResultImpl *MCDResult;

/* Progress and cancellation: called as long stages advance (stage, done of total) and
 * before each GPU submission (stage "", done and total 0). Returning false cancels the
 * run: mcdRunMethod then fails with MCD_ERROR_CANCELLED and writes nothing to its output.
 * Called on the thread that runs the method. */
typedef bool (*MCDProgressFunction)(void *userPtr, const char *stage, int done, int total);

/* The calling thread's last error since the last mcdGetError (MCD_ERROR_NONE: none), with
 * its message when `message` is not NULL ("" for none); clears it. */
MCDError mcdGetError(const char **message);
/* The error code's name ("invalid argument", ...). */
const char *mcdErrorName(MCDError code);
/* "major.minor.patch". */
const char *mcdVersion(void);

/* Views over the caller's memory, packed. */
MCDView mcdInterleaved(void *data, MCDFormat format, int width, int height, int channels);
MCDView mcdPlanar(void *data, MCDFormat format, int width, int height, int channels);

/* A Vulkan device: `name` an index or a case-insensitive name substring; NULL or "":
 * $MCD_DEVICE, then the best device. */
MCDDevice mcdNewDevice(const char *name);
void mcdReleaseDevice(MCDDevice device);
const char *mcdGetDeviceName(MCDDevice device);

/* A frame of named layers (the README's names: color, albedo, normal, depth, variance,
 * ...). mcdSetFrameLayer borrows the view's memory: nothing is copied; each run reads the
 * layers its method uses, so the memory must stay valid while a run on the frame is under
 * way. The first layer sets the frame's size. */
MCDFrame mcdNewFrame(void);
void mcdReleaseFrame(MCDFrame frame);
bool mcdSetFrameLayer(MCDFrame frame, const char *layer, const MCDView *view);
int mcdGetFrameWidth(MCDFrame frame);
int mcdGetFrameHeight(MCDFrame frame);
/* The layers' names, sorted: index 0 .. count - 1 (NULL outside). */
int mcdGetFrameLayerCount(MCDFrame frame);
const char *mcdGetFrameLayerName(MCDFrame frame, int index);
/* A layer's channels (0 and MCD_ERROR_MISSING_LAYER when the frame has none). */
int mcdGetFrameLayerChannels(MCDFrame frame, const char *layer);
/* Copy a layer into the caller's view (the frame's size and the layer's channels). */
bool mcdCopyFrameLayer(MCDFrame frame, const char *layer, const MCDView *output);

/* The methods: "auto" first, then the rest in the command line's order. */
int mcdGetMethodCount(void);
const char *mcdGetMethodName(int index);

/* A method by name, its parameters at their defaults. Names are the command line's
 * (--kappa is "kappa"); a value of the wrong type or outside the range is refused. */
MCDMethod mcdNewMethod(const char *name);
void mcdReleaseMethod(MCDMethod method);
const char *mcdGetMethodSummary(MCDMethod method);
bool mcdSetMethodBool(MCDMethod method, const char *param, bool value);
bool mcdSetMethodInt(MCDMethod method, const char *param, int value);
/* A whole number sets an integer parameter too. */
bool mcdSetMethodFloat(MCDMethod method, const char *param, double value);
bool mcdSetMethodString(MCDMethod method, const char *param, const char *value);
/* `text` read as the parameter's type ("0.5", "true", "swt"). */
bool mcdSetMethodText(MCDMethod method, const char *param, const char *text);
/* The parameters: names by index, and a value as text. */
int mcdGetMethodParamCount(MCDMethod method);
const char *mcdGetMethodParamName(MCDMethod method, int index);
const char *mcdGetMethodParamText(MCDMethod method, const char *param);
void mcdSetMethodProgressFunction(MCDMethod method, MCDProgressFunction function,
                                  void *userPtr);

/* Run the method on the frame. `output` (NULL: keep the result in the MCDResult; a view
 * whose data is NULL is refused) must be the frame's size with the color's channels, or one
 * more for the result's alpha (the frame's, alpha-rim's shares moved; 1 where it has none);
 * it is written only when the run succeeds. An output without the alpha channel runs without
 * alpha-rim (its moved alpha would not reach the caller; the plan says so). NULL on failure. */
MCDResult mcdRunMethod(MCDMethod method, MCDDevice device, MCDFrame frame,
                       const MCDView *output);
void mcdReleaseResult(MCDResult result);
/* What ran: the method's name; auto's "auto" when it combined candidates (listed by
 * mcdGetResultCandidate), else the method it picked. */
const char *mcdGetResultMethod(MCDResult result);
int mcdGetResultCandidateCount(MCDResult result);
const char *mcdGetResultCandidate(MCDResult result, int index);
/* The plan (what ran and why) and the warnings, line by line. */
int mcdGetResultPlanCount(MCDResult result);
const char *mcdGetResultPlanLine(MCDResult result, int index);
int mcdGetResultWarningCount(MCDResult result);
const char *mcdGetResultWarning(MCDResult result, int index);
double mcdGetResultWallMs(MCDResult result);
double mcdGetResultGpuMs(MCDResult result);
/* The result's image (a run without an output view) into the caller's view, as
 * mcdRunMethod's output. Refused without the alpha channel when alpha-rim moved light and
 * alpha into pixels of alpha 0: that colour needs its alpha (pass a view with one more
 * channel, or run with alpha-rim 0 or with a 3-channel output view). */
bool mcdCopyResultImage(MCDResult result, const MCDView *output);

#ifdef __cplusplus
}
#endif

#endif /* MCDENOISE_C_H */
