#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "rhf/terms.h"

// One invocation per (PIX pixels of a row, window row dy >= 0): x across, strip row and
// dy from the grid; the rows dy < 0 are the same terms seen from the candidate
// (distance.comp). The loops are unrolled so the lane's arrays stay in registers. On
// lavapipe the loads dominate: the histograms are read as texel buffers (gathered as
// vectors), and the lane's pixels share the candidates' bins (8 pixels per lane measured
// fastest, docs/performance.md). Bins that no pixel pair of the lane counts are left out
// (MayCount, from blockmax.comp's maxima).
layout(local_size_x = RHF_TERMS_LOCAL_SIZE) in;
layout(constant_id = RHF_TERMS_SPEC_SEARCH_HALF) const int B = 6;
// The histogram buffers in use: lavapipe runs every side of a branch, so a plane read
// through a switch over 6 buffers cost 6 fetches, and each unused buffer's ACCUMULATE one
// masked plane; with the count known when the pipeline is built they compile away.
layout(constant_id = RHF_TERMS_SPEC_SLOTS) const int SLOTS = RHF_HIST_SLOTS;
const int SIDE = 2 * B + 1;
layout(binding = RHF_TERMS_HIST + 0) uniform samplerBuffer hist0;
layout(binding = RHF_TERMS_HIST + 1) uniform samplerBuffer hist1;
layout(binding = RHF_TERMS_HIST + 2) uniform samplerBuffer hist2;
layout(binding = RHF_TERMS_HIST + 3) uniform samplerBuffer hist3;
layout(binding = RHF_TERMS_HIST + 4) uniform samplerBuffer hist4;
layout(binding = RHF_TERMS_HIST + 5) uniform samplerBuffer hist5;
// A storage buffer: lavapipe (Mesa 22.3) crashed building the pipeline with a seventh
// texel buffer here.
layout(std430, binding = RHF_TERMS_BLOCKMAX) readonly buffer BlockMax { float blockMax[]; };
layout(std430, binding = RHF_TERMS_SUM) writeonly buffer TermSum { float termSum[]; };
layout(std430, binding = RHF_TERMS_COUNT) writeonly buffer TermCount { float termCount[]; };

// Plane `plane` of pixel `pixel`, from the buffer that holds that plane.
float Hist(int plane, int pixel) {
    int slot = SLOTS == 1 ? 0 : plane / push.planesPerSlot;
    int at = (plane - slot * push.planesPerSlot) * (push.width * push.height) + pixel;
    if (SLOTS == 1 || slot == 0) return texelFetch(hist0, at).r;
    if (SLOTS == 2 || slot == 1) return texelFetch(hist1, at).r;
    if (SLOTS == 3 || slot == 2) return texelFetch(hist2, at).r;
    if (SLOTS == 4 || slot == 3) return texelFetch(hist3, at).r;
    if (SLOTS == 5 || slot == 4) return texelFetch(hist4, at).r;
    return texelFetch(hist5, at).r;
}

// The sample count of pixel `pixel`, times histScale: the count plane is the last, so it is
// in the last buffer, known when the pipeline is built (one fetch, not one per buffer).
float Count(int pixel) {
    int at = (push.binPlanes - (SLOTS - 1) * push.planesPerSlot) * (push.width * push.height) +
             pixel;
    float n = SLOTS == 1   ? texelFetch(hist0, at).r
              : SLOTS == 2 ? texelFetch(hist1, at).r
              : SLOTS == 3 ? texelFetch(hist2, at).r
              : SLOTS == 4 ? texelFetch(hist3, at).r
              : SLOTS == 5 ? texelFetch(hist4, at).r
                           : texelFetch(hist5, at).r;
    return n * push.histScale;
}

// A lane owns PIX consecutive pixels of a row: the candidates of its window row then share
// their bins between the lane's pixels (PIX + 2b reads for PIX x (2b+1) terms per bin).
const int PIX = RHF_TERMS_PIXELS_PER_LANE;
const int SPAN = PIX + 2 * B;
float sum[PIX * SIDE], count[PIX * SIDE], np[PIX], nq[SPAN], hp[PIX], hq[SPAN];

int x0Lane, yLane, qyLane;  // the lane's first pixel and its candidates' row

// With the veto on, the saturated bins (the last two of each colour: samples above the
// histogram's range M) are added first, by MarkVetoedPairs, and skipped by ACCUMULATE.
bool Saturated(int plane) {
    int perColour = push.binPlanes / 3;
    return push.brightVeto > 0.0 && plane % perColour >= perColour - 2;
}

// A bin, scaled; -FLT_MAX where the count n is 0, so that h_p + h_q > 1 fails for every
// pair with an empty pixel or candidate (bins are finite and >= 0) and AddTerms needs no
// test of the counts: 104 fewer compares per bin, the same terms.
float Bin(float n, float h) {
    return n != 0.0 ? h * push.histScale : -3.40282347e38;
}

// Add one bin's terms, from hp and hq, for every (pixel, candidate) of the lane.
void AddTerms() {
    [[unroll]] for (int j = 0; j < PIX; ++j)
        [[unroll]] for (int k = 0; k < SIDE; ++k) {
            float both = hp[j] + hq[j + k];
            if (both > 1.0) {  // never with an empty pixel or candidate (Bin)
                // precise: a contracted fma(a, b, -c * d) leaves a rounding error where the
                // two products are equal (a pixel against itself), not 0.
                precise float d = nq[j + k] * hp[j] - np[j] * hq[j + k];
                sum[j * SIDE + k] += d * d / (np[j] * nq[j + k] * both);
                count[j * SIDE + k] += 1.0;
            }
        }
}

// Whether a pair of the lane may count bin plane `plane`: its pixels' largest bin plus
// their candidates' largest (from the maxima of blockmax.comp: the lane's block and the
// blocks its candidates fall in, clamped to the row) is above 1. Rounding is monotone, so
// no pair's h_p + h_q exceeds that sum: where it is <= 1 AddTerms would add nothing, and
// leaving the bin out gives the same bits. At low spp a lane counts few of the bins.
const int QB = (B + PIX - 1) / PIX;  // candidate blocks on each side
bool MayCount(int plane) {
    int blocks = (push.width + PIX - 1) / PIX, block = x0Lane / PIX;
    int pBase = (plane * push.height + yLane) * blocks;
    int qBase = (plane * push.height + qyLane) * blocks;
    float maxP = blockMax[pBase + block], maxQ = -3.40282347e38;
    [[unroll]] for (int i = -QB; i <= QB; ++i)
        maxQ = max(maxQ, blockMax[qBase + clamp(block + i, 0, blocks - 1)]);
    return maxP + maxQ > 1.0;
}

// Load hp and hq from plane offset `base` of texel buffer `h`.
#define LOAD_BIN(h, base)                                                                \
    {                                                                                    \
        [[unroll]] for (int j = 0; j < PIX; ++j)                                         \
            hp[j] = Bin(np[j], texelFetch(h, base + pRow + min(x0 + j, push.width - 1)).r); \
        [[unroll]] for (int m = 0; m < SPAN; ++m)                                        \
            hq[m] = Bin(nq[m],                                                           \
                        texelFetch(h, base + qRow + clamp(x0 + m - B, 0, push.width - 1)).r); \
    }

// Add the terms of the bin planes buffer `h` (slot `slot`) holds, 32 planes at a time: the
// planes MayCount marks, in plane order. On lavapipe a branch runs whenever one lane of the
// vector takes it, but a loop stops when no lane is left in it: the loop over the marked
// planes runs as often as the busiest of the 8 lanes needs (14 of 54 planes above).
#define ACCUMULATE(h, slot)                                                              \
    {                                                                                    \
        int first = slot * push.planesPerSlot;                                           \
        int last = min(first + push.planesPerSlot, push.binPlanes);                      \
        for (int chunk = first; chunk < last; chunk += 32) {                             \
            uint marked = 0u;                                                            \
            for (int plane = chunk; plane < min(chunk + 32, last); ++plane)              \
                /* the saturated planes were added first, by MarkVetoedPairs */          \
                if (!Saturated(plane) && MayCount(plane)) marked |= 1u << (plane - chunk); \
            while (marked != 0u) {                                                       \
                int plane = chunk + findLSB(marked);                                     \
                marked &= marked - 1u;                                                   \
                LOAD_BIN(h, (plane - first) * pixels)                                    \
                AddTerms();                                                              \
            }                                                                            \
        }                                                                                \
    }

// The veto's mark for each (pixel, candidate) of the lane, a bit each.
const int VETO_WORDS = (PIX * SIDE + 31) / 32;
uint vetoed[VETO_WORDS];

// Add the saturated bins' terms (those MayCount marks) and mark the pairs whose sum exceeds
// brightVeto x the harmonic mean of their counts; the other bins are added after.
void MarkVetoedPairs(int pRow, int qRow) {
    int perColour = push.binPlanes / 3, low = max(perColour - 2, 0), each = perColour - low;
    uint marked = 0u;  // bit c * each + b - low for bin b of colour c
    for (int c = 0; c < 3; ++c)
        for (int b = low; b < perColour; ++b)
            if (MayCount(c * perColour + b)) marked |= 1u << (c * each + b - low);
    while (marked != 0u) {
        int i = findLSB(marked);
        marked &= marked - 1u;
        int plane = (i / each) * perColour + low + i % each;
        [[unroll]] for (int j = 0; j < PIX; ++j)
            hp[j] = Bin(np[j], Hist(plane, pRow + min(x0Lane + j, push.width - 1)));
        [[unroll]] for (int m = 0; m < SPAN; ++m)
            hq[m] = Bin(nq[m], Hist(plane, qRow + clamp(x0Lane + m - B, 0, push.width - 1)));
        AddTerms();
    }
    [[unroll]] for (int i = 0; i < PIX * SIDE; ++i) {
        int j = i / SIDE, k = i % SIDE;
        float harmonic = 2.0 * np[j] * nq[j + k] / (np[j] + nq[j + k]);
        if (count[i] > 0.0 && sum[i] > push.brightVeto * harmonic)
            vetoed[i / 32] |= 1u << (i % 32);
    }
}

void main() {
    int x0 = int(gl_GlobalInvocationID.x) * PIX, r = int(gl_WorkGroupID.y),
        dy = int(gl_WorkGroupID.z);
    if (x0 >= push.width) return;
    int y = push.rowBase + r, qy = y + dy, pixels = push.width * push.height;
    x0Lane = x0;
    yLane = y;
    qyLane = qy;
    [[unroll]] for (int i = 0; i < PIX * SIDE; ++i) {
        sum[i] = 0.0;
        count[i] = 0.0;
    }
    [[unroll]] for (int i = 0; i < VETO_WORDS; ++i) vetoed[i] = 0u;
    if (qy >= 0 && qy < push.height) {
        int pRow = y * push.width, qRow = qy * push.width;
        // Counts; 0 marks a pixel or candidate outside the image (never counted).
        [[unroll]] for (int j = 0; j < PIX; ++j)
            np[j] = x0 + j < push.width ? Count(pRow + x0 + j) : 0.0;
        [[unroll]] for (int m = 0; m < SPAN; ++m) {
            int qx = x0 + m - B;
            nq[m] = qx >= 0 && qx < push.width ? Count(qRow + qx) : 0.0;
        }
        if (push.brightVeto > 0.0) MarkVetoedPairs(pRow, qRow);
        // The count plane is last, so the bin planes may use one buffer fewer than SLOTS.
        int slots = (push.binPlanes + push.planesPerSlot - 1) / push.planesPerSlot;
        ACCUMULATE(hist0, 0)
        if (SLOTS > 1 && slots > 1) ACCUMULATE(hist1, 1)
        if (SLOTS > 2 && slots > 2) ACCUMULATE(hist2, 2)
        if (SLOTS > 3 && slots > 3) ACCUMULATE(hist3, 3)
        if (SLOTS > 4 && slots > 4) ACCUMULATE(hist4, 4)
        if (SLOTS > 5 && slots > 5) ACCUMULATE(hist5, 5)
    }
    [[unroll]] for (int j = 0; j < PIX; ++j)
        [[unroll]] for (int k = 0; k < SIDE; ++k) {
            if (x0 + j >= push.width) continue;
            int at = ((dy * SIDE + k) * push.rows + r) * push.width + x0 + j;
            int i = j * SIDE + k;
            termSum[at] = sum[i];
            termCount[at] = (vetoed[i / 32] & (1u << (i % 32))) != 0u ? -1.0 : count[i];
        }
}
