// One pass of one level of the stationary wavelet synthesis (swt_synthesize.comp): bindings
// and push constants. Layout and the shared constants in swt.h.
#ifndef MCD_SHADERS_WAVELET_SWT_SYNTHESIZE_H
#define MCD_SHADERS_WAVELET_SWT_SYNTHESIZE_H

#define WAVELET_SWT_SYNTHESIZE_SRC 0  // read as a float texel buffer
#define WAVELET_SWT_SYNTHESIZE_DST 1
#define WAVELET_SWT_SYNTHESIZE_BINDINGS 2
// Invocations along x per workgroup, 4 positions each.
#define WAVELET_SWT_SYNTHESIZE_LOCAL_SIZE 64

#ifdef __cplusplus
namespace mcd::shader {
struct WaveletSwtSynthesizePush {
#else
layout(push_constant) uniform WaveletSwtSynthesizePush {
#endif
    int width;
    int height;
    int step;   // 2^level
    int flags;  // WAVELET_SWT_TRANSFORM_*
    // Float offsets: a pass reads channel c's planes at srcBase + c srcChannel (+ k planes)
    // and srcLow, and writes them at dstBase + c dstChannel (+ k planes) and dstLow.
    int srcBase;
    int srcChannel;
    int srcLow;  // offset of the low plane from the channel's start (columns passes)
    int dstBase;
    int dstChannel;
    int dstLow;  // unused (swt_analyze.h's columns pass writes one)
#ifdef __cplusplus
};
static_assert(sizeof(WaveletSwtSynthesizePush) == 40);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
