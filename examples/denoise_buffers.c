/* Denoise a buffer in memory through the C API: denoise_buffers_c [METHOD]
 * A noisy gradient (exponential noise, 8 samples a pixel) in a planar float buffer is
 * denoised into another; prints the error before and after and fails if it did not fall. */
#include <mcdenoise/mcdenoise_c.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum { W = 80, H = 48, SPP = 8 };

static float color[3 * W * H], truth[3 * W * H], output[3 * W * H];

/* A smooth image and a Monte Carlo estimate of it, planar [c][y][x]. */
static void Render(void) {
    unsigned state = 12345u;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                int i = (c * H + y) * W + x;
                float value = 0.1f + (float)x / W * (0.5f + 0.2f * c) + 0.3f * y / H;
                float sum = 0;
                for (int s = 0; s < SPP; ++s) {
                    state = state * 1664525u + 1013904223u;
                    float u = ((state >> 8) + 0.5f) / 16777216.f;
                    sum += value * -logf(u); /* exponential noise of mean 1 */
                }
                color[i] = sum / SPP;
                truth[i] = value;
            }
}

static double RelMse(const float *image) {
    double sum = 0;
    for (int i = 0; i < 3 * W * H; ++i) {
        double d = image[i] - truth[i];
        sum += d * d / (truth[i] * truth[i] + 1e-2);
    }
    return sum / (3.0 * W * H);
}

/* Print the thread's error, if any, and say whether there was one. */
static int Failed(const char *what) {
    const char *message;
    MCDError code = mcdGetError(&message);
    if (code == MCD_ERROR_NONE) return 0;
    fprintf(stderr, "%s: error (%s): %s\n", what, mcdErrorName(code), message);
    return 1;
}

int main(int argc, char **argv) {
    Render();
    MCDDevice device = mcdNewDevice(NULL);
    MCDFrame frame = mcdNewFrame();
    MCDMethod method = mcdNewMethod(argc > 1 ? argv[1] : "bayes");
    MCDView in = mcdPlanar(color, MCD_FORMAT_FLOAT, W, H, 3);
    MCDView out = mcdPlanar(output, MCD_FORMAT_FLOAT, W, H, 3);
    MCDResult result = NULL;
    int status = 1;
    if (device && frame && method && mcdSetFrameLayer(frame, "color", &in))
        result = mcdRunMethod(method, device, frame, &out);
    if (!Failed("denoise_buffers_c") && result) {
        double before = RelMse(color), after = RelMse(output);
        printf("%s on %s, %dx%d, %.1f ms: relMSE %.4f -> %.4f\n", mcdGetResultMethod(result),
               mcdGetDeviceName(device), W, H, mcdGetResultWallMs(result), before, after);
        status = after < before ? 0 : 1;
    }
    mcdReleaseResult(result);
    mcdReleaseMethod(method);
    mcdReleaseFrame(frame);
    mcdReleaseDevice(device);
    return status;
}
