#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

// The forward DWT: plain taps.
#define WAVELET_SQUARED 0
#define WAVELET_LOW_SUM 0.0
#define WAVELET_HIGH_SUM 0.0
#include "wavelet/wavelet.h"
#include "wavelet/analyze.h"

layout(local_size_x = WAVELET_LOCAL_SIZE) in;
layout(constant_id = WAVELET_SPEC_AXIS) const int AXIS = WAVELET_AXIS_ROWS;
layout(constant_id = WAVELET_SPEC_VEC4) const int VEC4 = 0;
// Scalar and vec4 views of the same buffers (vec4 only with strides that are multiples of 4).
layout(std430, binding = WAVELET_LINES_SRC) readonly buffer Src { float src[]; };
layout(std430, binding = WAVELET_LINES_SRC) readonly buffer Src4 { vec4 src4[]; };
layout(std430, binding = WAVELET_LINES_DST) writeonly buffer Dst { float dst[]; };
layout(std430, binding = WAVELET_LINES_DST) writeonly buffer Dst4 { vec4 dst4[]; };

#include "wavelet/convolve.glsl"
