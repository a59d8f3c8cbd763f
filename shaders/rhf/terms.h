// RHF pixel terms (issue #4, paper eq. 3 with counts): for every offset o = (dx, dy)
// with dy in 0..b, |dx| <= b, and every pixel p of a strip of rows, the sum over
// the 3n bins of (n_q h_p[i] - n_p h_q[i])^2 / (n_p n_q (h_p[i] + h_q[i])), q = p + o,
// counted where h_p[i] + h_q[i] > 1 and both counts are non-zero, and how many were
// counted; planes [dy][dx + b]. The term is symmetric in p and q, bit for bit, so the
// offsets with dy < 0 are read at q with -o and never computed. Box-summed over a patch
// later (distance.comp), so no term is computed twice. With brightVeto > 0, a pair whose
// terms in the saturated bins (the last two of each colour) sum to more than
// brightVeto x 2 n_p n_q / (n_p + n_q) gets count -1: the mark that vetoes every patch
// pair holding it (cpu_reference/rhf.h, RhfPatchDistance).
// Histograms are planar [plane][y][x], split over up to RHF_HIST_SLOTS buffers of
// planesPerSlot planes each (one binding holds at most 128 MiB on lavapipe).
#ifndef MCD_SHADERS_RHF_TERMS_H
#define MCD_SHADERS_RHF_TERMS_H

#define RHF_HIST_SLOTS 6  // with the two outputs and the bin maxima, 9 bindings
#define RHF_TERMS_HIST 0  // slots 0..RHF_HIST_SLOTS-1
#define RHF_TERMS_SUM 6
#define RHF_TERMS_COUNT 7
#define RHF_TERMS_BLOCKMAX 8  // blockmax.comp's maxima of the bins, to leave bins out
#define RHF_TERMS_BINDINGS 9
#define RHF_TERMS_LOCAL_SIZE 64
#define RHF_TERMS_PIXELS_PER_LANE 8   // consecutive pixels of a row per lane
#define RHF_TERMS_SPEC_SEARCH_HALF 0  // b, so a lane keeps one window row in registers
#define RHF_TERMS_SPEC_SLOTS 1        // histogram buffers bound (1..RHF_HIST_SLOTS)

#ifdef __cplusplus
#include <cstddef>
namespace mcd::shader {
struct RhfTermsPush {
#else
layout(push_constant) uniform RhfTermsPush {
#endif
    int width;  // of the scale's image
    int height;
    int binPlanes;      // 3n; plane 3n is the sample count
    float brightVeto;   // 0: no veto
    int rowBase;        // first image row of the strip
    int rows;           // rows in the strip
    int planesPerSlot;  // histogram planes per buffer
    float histScale;    // the scale's count-preserving factor, applied to bins and counts
#ifdef __cplusplus
};
static_assert(sizeof(RhfTermsPush) == 32);
static_assert(offsetof(RhfTermsPush, histScale) == 28);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
