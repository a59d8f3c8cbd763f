#version 450
#extension GL_GOOGLE_include_directive : require

#include "bayes/table.h"
#include "bayes/model.glsl"

// x: table entry, y: band.
layout(local_size_x = BAYES_TABLE_LOCAL_SIZE) in;
layout(std430, binding = BAYES_TABLE_PARAMS) readonly buffer Params { float params[]; };
layout(std430, binding = BAYES_TABLE_OUT) writeonly buffer Table { float table[]; };

void main() {
    int i = int(gl_GlobalInvocationID.x), band = int(gl_WorkGroupID.y);
    if (i >= BAYES_TABLE_SIZE || band >= push.bands) return;
    int at = band * BAYES_PARAM_STRIDE;
    float sn = params[at + 0], pn = params[at + 1], sc = params[at + 2], pc = params[at + 3];
    int fit = int(params[at + 4]);
    float y = params[at + 6] * sinh(float(i) * params[at + 7]);
    float value = 0.0;
    if (fit == BAYES_FIT_NO_NOISE)
        value = y;
    else if (fit != BAYES_FIT_NO_SIGNAL && fit != BAYES_FIT_EMPTY && i > 0)
        value = BayesPosteriorMean(y, sn, pn, sc, pc);
    table[band * BAYES_TABLE_SIZE + i] = value;
}
