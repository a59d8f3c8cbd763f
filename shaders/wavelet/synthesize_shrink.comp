#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#define WAVELET_LINES_EXTRA_PUSH float cs;
#define WAVELET_SYNTHESIZE_SHRINK
#include "wavelet/wavelet.h"
#include "wavelet/synthesize_shrink.h"

layout(std430, binding = WAVELET_SYNTHESIZE_SHRINK_VARIANCE) readonly buffer Variance {
    float variance[];
};

#include "wavelet/synthesize.glsl"
