// The pivot-image filter's parameters (Ershov et al., section 4), as the GPU pipeline
// (host/methods/pivot.h), the front end (host/api/method_pivot.cpp) and the CPU reference
// (cpu_reference/pivot_filter.h) read them: a layout, like a kernel's push-constant header.
// The initializers are the defaults the command line shows.
#pragma once

namespace mcd {

// planefit: the paper's plane fits (eqs. 10-13); bilateral: the cross-bilateral baseline
// of section 4.1.
enum class PivotFilter { PlaneFit, Bilateral };

struct PivotParams {
    PivotFilter filter = PivotFilter::PlaneFit;
    float floor = 1e-3f;  // pixels with pivot <= floor x channel mean have no z
    // planefit
    int maxRadius = 30;         // largest half-size of the square (paper: 30-40)
    float targetNoise = 0.02f;  // relative std of a centre's fit that stops growth
    // Relative std above which a pixel is not fitted (section 4.2's threshold). Large: small
    // values leave the heavy-tailed scenes' fireflies, which carry the energy, unfitted and
    // darken them (docs/methods/pivot.md).
    float goodNoise = 100.f;
    float disagreement = 0.1f;  // square-vs-quadrant limit at the centre, relative
    // Eq. 10's robustness constant; k = 1 darkens (it down-weights the bright tail of the
    // noise), 0 and 0.3 measure the same (docs/methods/pivot.md).
    float k = 0.3f;
    // Multiplies sigma in eq. 10. With heavy-tailed noise the pixels that carry the energy
    // (fireflies) have the largest sigma, so 1 (the paper) darkens their plane; 0 measured
    // better PSNR on the scenes above (docs/methods/pivot.md).
    float sigmaWeight = 0.f;
    // Sigmas of the shading-edge test (shaders/pivot/edge.glsl): a fit leaves out, and a
    // pixel does not gather, what lies across an edge its colour shows and the pivot does
    // not (a sun patch on a floor). 0: off.
    float edge = 4.f;
    // bilateral: window half-size, spatial sigma = radius / 2, range sigma on the relative
    // difference of the pivot's channel mean.
    int bilateralRadius = 8;
    float sigmaRange = 0.2f;
    // Beyond the paper, applied by the front end (host/api/method_pivot.cpp) after the
    // filter: the input's local means restored over tents of radius 8, then 2 x meanRadius
    // (host/common/local_mean.h; 0: off). The fits' robust weights (k) and the
    // noise threshold leave out the bright tail of heavy-tailed noise and the pixels of
    // small highlights, which darkened such frames by up to half (issue 29).
    int meanRadius = 8;
};

}  // namespace mcd
