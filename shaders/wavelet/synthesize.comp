#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "wavelet/wavelet.h"
#include "wavelet/synthesize.h"

#include "wavelet/synthesize.glsl"
