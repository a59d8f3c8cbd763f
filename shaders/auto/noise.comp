#version 450
#extension GL_GOOGLE_include_directive : require

#include "auto/noise.h"

layout(local_size_x = AUTO_LOCAL_SIZE) in;
layout(std430, binding = AUTO_NOISE_COLOR) readonly buffer Color { float color[]; };
layout(std430, binding = AUTO_NOISE_ALBEDO) readonly buffer Albedo { float albedo[]; };
layout(std430, binding = AUTO_NOISE_OUTPUT) writeonly buffer Output { float outputs[]; };

int w, h, c;

bool finite(float v) {
    return !(isnan(v) || isinf(v));
}

// The divisor at (x, y): the albedo where it is above the floor, else 1.
float scaleAt(int x, int y) {
    if (push.albedoChannels == 0) return 1.0;
    int ac = min(c, push.albedoChannels - 1);
    float a = albedo[(ac * h + y) * w + x];
    return a > float(AUTO_NOISE_ALBEDO_FLOOR) && finite(a) ? a : 1.0;
}

float zAt(int x, int y) {
    return color[(c * h + y) * w + x] / scaleAt(x, y);
}

void main() {
    int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
    w = push.width;
    h = push.height;
    c = int(gl_WorkGroupID.z);
    if (x >= w) return;
    int r = push.radius;
    float values[AUTO_NOISE_MAX_WINDOW];
    int count = 0;
    for (int v = max(0, y - r); v <= min(h - 1, y + r); ++v)
        for (int u = max(0, x - r); u <= min(w - 1, x + r); ++u) {
            float sum = 0.0;
            int n = 0;
            for (int dv = -1; dv <= 1; ++dv)
                for (int du = -1; du <= 1; ++du) {
                    int uu = u + du, vv = v + dv;
                    if ((du == 0 && dv == 0) || uu < 0 || vv < 0 || uu >= w || vv >= h)
                        continue;
                    sum += zAt(uu, vv);
                    ++n;
                }
            if (n == 0) continue;
            float residual = zAt(u, v) - sum / float(n);
            float r2 = residual * residual / (1.0 + 1.0 / float(n));
            if (!finite(r2)) continue;
            // Insertion into the sorted prefix.
            int i = count;
            while (i > 0 && values[i - 1] > r2) {
                values[i] = values[i - 1];
                --i;
            }
            values[i] = r2;
            ++count;
        }
    float s = scaleAt(x, y);
    outputs[(c * h + y) * w + x] =
        count > 0 ? values[count / 2] / float(AUTO_NOISE_MEDIAN_CHI2) * s * s : 0.0;
}
