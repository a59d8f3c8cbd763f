#version 450
#extension GL_GOOGLE_include_directive : require

#include "tracing/gather.h"

layout(local_size_x = TRACING_LOCAL_SIZE) in;
layout(binding = TRACING_GATHER_SURFACES) uniform samplerBuffer surfaces;
layout(binding = TRACING_GATHER_DIRECTION) uniform samplerBuffer directions;
layout(binding = TRACING_GATHER_PDF) uniform samplerBuffer pdfs;
layout(binding = TRACING_GATHER_RADIANCE) uniform samplerBuffer radiances;
layout(binding = TRACING_GATHER_OWN) uniform samplerBuffer owns;
layout(std430, binding = TRACING_GATHER_OUT) writeonly buffer Out { float outImage[]; };

const float kPi = 3.14159265358979323846;

int planeSize, fieldSize;  // rows x width; spp x rows x width

float Surf(int plane, int i) { return texelFetch(surfaces, plane * planeSize + i).r; }
vec3 Surf3(int plane, int i) {
    return vec3(Surf(plane, i), Surf(plane + 1, i), Surf(plane + 2, i));
}

// A 3-field value of the sample at `at` (s * planeSize + pixel).
vec3 Field3(samplerBuffer fields, int at) {
    return vec3(texelFetch(fields, at).r, texelFetch(fields, fieldSize + at).r,
                texelFetch(fields, 2 * fieldSize + at).r);
}

// reflect(-wo, n) = 2 (wo . n) n - wo: the mirror direction, the glossy lobe's axis.
vec3 MirrorAxis(vec3 n, vec3 wo) { return 2.0 * dot(wo, n) * n - wo; }

// The pixel p: its geometry, its material's channel means (eq. 17's scalar lobe) and the
// normalisation of its vMF lobe, kappa / (2 pi (1 - exp(-2 kappa))).
vec3 pNormal, pAxis, pDiffuse, pGlossy;
float pMeanDiffuse, pMeanGlossy, pKappa, pVmfNorm, scale;

// p's vMF lobe towards u about `axis` (p's own or a neighbour's mirror direction).
float Vmf(vec3 axis, vec3 u) { return pVmfNorm * exp(pKappa * (dot(axis, u) - 1.0)); }

// F's lobe: p's material on the geometry (normal n, mirror axis) of a neighbour; 0 below
// that neighbour's horizon (eq. 14's Theta).
float ScalarLobe(vec3 n, vec3 axis, vec3 u) {
    float cosN = dot(n, u);
    if (!(cosN > 0.0)) return 0.0;
    return pMeanDiffuse * cosN / kPi + pMeanGlossy * Vmf(axis, u);
}

// w(p <- p', u) of eq. 17 given p's lobe `here` towards u and p's exponent of the fixed
// part for the neighbour.
float Weight(float here, float fixedExponent, vec3 n, vec3 axis, vec3 u) {
    float there = ScalarLobe(n, axis, u);
    if (!(here > 0.0) || !(there > 0.0)) return 0.0;
    float exponent = fixedExponent;
    if (push.gamma > 0.0) {
        float ratio = there / here, f = max(ratio, 1.0 / ratio);
        exponent += push.gamma * f * f;
    }
    return scale * exp(-exponent);
}

void main() {
    if (int(gl_GlobalInvocationID.x) >= push.pixelCount) return;
    int k = push.pixelBase + int(gl_GlobalInvocationID.x);
    int w = push.width, rows = push.rows, spp = push.spp, radius = push.radius;
    planeSize = w * rows;
    fieldSize = spp * planeSize;
    int x = k % w, outRow = k / w, y = push.outRow0 + outRow;
    int i = y * w + x, outPlane = push.outRows * w;
    vec3 sum = vec3(0.0);
    if (!(Surf(TRACING_SURF_VALID, i) > 0.0)) {
        // Nothing to filter: the plain mean of the pixel's own values.
        for (int s = 0; s < spp; ++s) {
            int at = s * planeSize + i;
            sum += Field3(owns, at);
        }
        sum /= float(spp);
        outImage[k] = sum.r;
        outImage[outPlane + k] = sum.g;
        outImage[2 * outPlane + k] = sum.b;
        return;
    }
    pNormal = Surf3(TRACING_SURF_NORMAL, i);
    pAxis = MirrorAxis(pNormal, Surf3(TRACING_SURF_WO, i));
    pDiffuse = Surf3(TRACING_SURF_DIFFUSE, i);
    pGlossy = Surf3(TRACING_SURF_GLOSSY, i);
    pMeanDiffuse = (pDiffuse.r + pDiffuse.g + pDiffuse.b) / 3.0;
    pMeanGlossy = (pGlossy.r + pGlossy.g + pGlossy.b) / 3.0;
    pKappa = Surf(TRACING_SURF_KAPPA, i);
    if (pKappa <= 0.0) {
        pKappa = 0.0;
        pVmfNorm = 1.0 / (4.0 * kPi);
    } else {
        // 1 - exp(-2 kappa) without cancellation for small kappa (its series to x^4).
        float t = 2.0 * pKappa;
        float oneMinus = t < 0.01 ? t * (1.0 - t * (0.5 - t * (1.0 / 6.0 - t / 24.0)))
                                  : 1.0 - exp(-t);
        pVmfNorm = pKappa / (2.0 * kPi * oneMinus);
    }

    // The fixed parts of eq. 17 over the disk, and C_p from their sum. The loops run the
    // same counts in every lane; what a lane skips it skips inside.
    float fixedSum = 0.0;
    for (int dy = -radius; dy <= radius; ++dy) {
        int ny = y + dy;
        for (int dx = -radius; dx <= radius; ++dx) {
            int nx = x + dx, d2 = dx * dx + dy * dy;
            if (d2 == 0 || d2 > radius * radius || nx < 0 || nx >= w || ny < 0 || ny >= rows)
                continue;
            int j = ny * w + nx;
            if (!(Surf(TRACING_SURF_VALID, j) > 0.0)) continue;
            float nn = dot(pNormal, Surf3(TRACING_SURF_NORMAL, j));
            fixedSum += exp(-(push.alpha * float(d2) + push.beta * (1.0 - nn)));
        }
    }
    scale = fixedSum > 0.0 ? min(1.0, push.selfFloor / fixedSum) : 1.0;

    // Eq. 16 as sum_s own_s - sum_p' sum_s w(p <- p', u_s) own_s: the disk is walked once
    // per chunk of own samples held in private arrays, not once per sample. A sample with no
    // record, below p's horizon or with a zero own value takes no weight (its self weight
    // is 1 or does not matter); a non-finite channel of own passes through ownSum alone
    // (self x inf = inf for self in (0, 1]; NaN stays NaN).
    vec3 ownSum = vec3(0.0), taken = vec3(0.0);
    vec3 chunkU[TRACING_OWN_CHUNK], chunkOwn[TRACING_OWN_CHUNK];
    float chunkHere[TRACING_OWN_CHUNK];
    for (int s0 = 0; s0 < spp; s0 += TRACING_OWN_CHUNK) {
        int count = min(TRACING_OWN_CHUNK, spp - s0);  // the same in every lane
        for (int c = 0; c < count; ++c) {
            int at = (s0 + c) * planeSize + i;
            vec3 own = Field3(owns, at), u = Field3(directions, at);
            ownSum += own;
            float here = ScalarLobe(pNormal, pAxis, u);
            vec3 finiteOwn = mix(own, vec3(0.0), bvec3(uvec3(isnan(own)) | uvec3(isinf(own))));
            bool weighed = texelFetch(pdfs, at).r > 0.0 && here > 0.0 &&
                          any(notEqual(finiteOwn, vec3(0.0)));
            chunkU[c] = u;
            chunkOwn[c] = finiteOwn;
            chunkHere[c] = weighed ? here : 0.0;
        }
        for (int dy = -radius; dy <= radius; ++dy) {
            int ny = y + dy;
            for (int dx = -radius; dx <= radius; ++dx) {
                int nx = x + dx, d2 = dx * dx + dy * dy;
                if (d2 == 0 || d2 > radius * radius || nx < 0 || nx >= w || ny < 0 ||
                    ny >= rows)
                    continue;
                int j = ny * w + nx;
                // The neighbour lends from the share of its samples that see a surface: its
                // weight in the self term is scaled by that share.
                float coverage = Surf(TRACING_SURF_VALID, j);
                if (!(coverage > 0.0)) continue;
                vec3 n = Surf3(TRACING_SURF_NORMAL, j);
                vec3 axis = MirrorAxis(n, Surf3(TRACING_SURF_WO, j));
                float fixedExponent =
                    push.alpha * float(d2) + push.beta * (1.0 - dot(pNormal, n));
                for (int c = 0; c < count; ++c) {
                    if (!(chunkHere[c] > 0.0)) continue;
                    taken += coverage * Weight(chunkHere[c], fixedExponent, n, axis, chunkU[c]) *
                             chunkOwn[c];
                }
            }
        }
    }
    ownSum -= taken;

    // Eq. 15's sum over the neighbours: their samples re-weighted for p (eq. 14).
    vec3 lent = vec3(0.0);
    for (int dy = -radius; dy <= radius; ++dy) {
        int ny = y + dy;
        for (int dx = -radius; dx <= radius; ++dx) {
            int nx = x + dx, d2 = dx * dx + dy * dy;
            if (d2 == 0 || d2 > radius * radius || nx < 0 || nx >= w || ny < 0 || ny >= rows)
                continue;
            int j = ny * w + nx;
            if (!(Surf(TRACING_SURF_VALID, j) > 0.0)) continue;
            vec3 n = Surf3(TRACING_SURF_NORMAL, j);
            vec3 axis = MirrorAxis(n, Surf3(TRACING_SURF_WO, j));
            float fixedExponent = push.alpha * float(d2) + push.beta * (1.0 - dot(pNormal, n));
            for (int s = 0; s < spp; ++s) {
                int at = s * planeSize + j;
                float pdf = texelFetch(pdfs, at).r;
                vec3 radiance =
                    Field3(radiances, at);
                if (!(pdf > 0.0) || isinf(pdf) || any(isnan(radiance)) || any(isinf(radiance)))
                    continue;
                vec3 u = Field3(directions, at);
                // p's f cos towards u, per channel and as F's scalar lobe.
                float cosN = dot(pNormal, u);
                if (!(cosN > 0.0)) continue;
                float vmf = Vmf(pAxis, u);
                float here = pMeanDiffuse * cosN / kPi + pMeanGlossy * vmf;
                float weight = Weight(here, fixedExponent, n, axis, u);
                if (weight == 0.0) continue;
                vec3 fcos = pDiffuse * (cosN / kPi) + pGlossy * vmf;
                lent += (weight / pdf) * fcos * radiance;
            }
        }
    }
    sum = (ownSum + lent) / float(spp);
    outImage[k] = sum.r;
    outImage[outPlane + k] = sum.g;
    outImage[2 * outPlane + k] = sum.b;
}
