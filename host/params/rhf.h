// Ray Histogram Fusion's parameters (Delbracio et al., IPOL 2015), as the GPU pipeline
// (host/methods/rhf.h), the front end (host/api/method_rhf.cpp) and the CPU reference
// (cpu_reference/rhf.h) all read them: a layout, like a kernel's push-constant header. The
// initializers are the defaults the command line shows.
#pragma once

namespace mcd {

struct RhfParams {
    int patchHalf = 1;       // w: patches are (2w+1)^2
    int searchHalf = 6;      // b: the search window is (2b+1)^2
    float threshold = 0.8f;  // kappa, on the normalised chi-square patch distance
    int knn = 2;             // nearest patches always averaged, finest scale only
    // Requested; see RhfScalesUsed. One, not the tool's two: with the scales aligned as
    // the tool aligns them (issue #20), one scale had the lower error in most cells of the
    // quality table and on an accumulated Cycles frame (docs/methods/rhf.md).
    int scales = 1;
    // The bright veto (beyond the authors' tool; 0 is theirs): a candidate patch is left
    // out when one pixel pair's counted terms in the saturated bins (the last two of each
    // colour: samples above the histogram's range M) sum to more than brightVeto x the
    // harmonic mean of the pair's sample counts (in the frame's counts at every scale).
    // The tool's distance is a mean over a patch's counted terms, so a visible light's large
    // terms are diluted by the zero terms of its alike neighbours and the light leaks into
    // dark patches at few samples; a lone firefly sample, at most 1 in its bins, stays below
    // the tool's "more than 1" and is still averaged away (README, "The bright veto").
    float brightVeto = 0.3f;
    // The pooled bright veto (beyond the tool; 0: off), finest scale: a candidate patch is
    // left out when the bright samples (the saturated bins' counts, summed over the colours)
    // pooled over its patch box, Q, and over the centre's, P, differ as rates over the
    // boxes' pixel counts aQ, aP (boxes cut at the frame's edges, so a border box is not
    // taken for a darker one): (P/aP - Q/aQ)^2 > brightPool (P/aP^2 + Q/aQ^2), which is
    // (P - Q)^2 > brightPool (P + Q) where both boxes are whole. A highlight's line whose
    // pixels each hold one bright sample adds no term to the distance nor to the bright veto (a
    // bin of one sample is not counted), so the dark patches of its window took it in: a block
    // the size of the window. Loose enough that a patch with a pair of fireflies (P - Q of two
    // samples, summed over three colours: 6) is still averaged at 6: a tighter bound kept the
    // fireflies that CutSpikes leaves as blotches; one way only (a bright patch may take in
    // darker ones) lost their energy to the restore's glow. Off by default: at 6 rows of the
    // heavy-tailed scenes got worse (docs/methods/rhf.md).
    float brightPool = 0.f;
    // Keep negative output values, as the authors' tool does. Off (beyond the tool): the
    // recombination's bicubic U overshoots below 0 at strong edges (README), and the GPU
    // pipeline clamps its output to 0 after the last stage, so `diff --method rhf` compares
    // raw stages. The CPU reference always returns the raw output.
    bool keepNegative = false;
    // The input's local means restored after the exact pixels (host/common/local_mean.h,
    // beyond the authors' tool): patch weighting averages a firefly into its dark
    // neighbours but not theirs into it, so heavy-tailed frames lose brightness. 0: off.
    int meanRadius = 8;
};

}  // namespace mcd
