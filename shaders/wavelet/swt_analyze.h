// One pass of one level of the stationary wavelet analysis (swt_analyze.comp): bindings,
// specialization constant and push constants. Layout and the shared constants in swt.h.
#ifndef MCD_SHADERS_WAVELET_SWT_ANALYZE_H
#define MCD_SHADERS_WAVELET_SWT_ANALYZE_H

#define WAVELET_SWT_ANALYZE_SRC 0  // read as a float texel buffer
#define WAVELET_SWT_ANALYZE_DST 1
#define WAVELET_SWT_ANALYZE_BINDINGS 2
// Invocations along x per workgroup, 4 positions each.
#define WAVELET_SWT_ANALYZE_LOCAL_SIZE 64

// Specialization constant beside swt.h's basis and axis.
#define WAVELET_SWT_ANALYZE_SPEC_SQUARED 2  // 1 squares every tap (variance analysis)

#ifdef __cplusplus
namespace mcd::shader {
struct WaveletSwtAnalyzePush {
#else
layout(push_constant) uniform WaveletSwtAnalyzePush {
#endif
    int width;
    int height;
    int step;   // 2^level
    int flags;  // WAVELET_SWT_TRANSFORM_*
    // Float offsets: a pass reads channel c's planes at srcBase + c srcChannel (+ k planes)
    // and srcLow, and writes them at dstBase + c dstChannel (+ k planes) and dstLow.
    int srcBase;
    int srcChannel;
    int srcLow;  // unused (swt_synthesize.h's columns pass reads one)
    int dstBase;
    int dstChannel;
    int dstLow;  // offset of the low plane from the channel's start (fused, columns)
#ifdef __cplusplus
};
static_assert(sizeof(WaveletSwtAnalyzePush) == 40);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
