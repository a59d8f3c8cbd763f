// The CPU reference's parameters for the GPU method's options, shared by the pivot tests.
#pragma once

#include "cpu_reference/pivot_filter.h"
#include "host/methods/pivot.h"

namespace mcd::test {

inline ref::PivotParams RefParams(const PivotOptions &o) {
    ref::PivotParams p;
    p.floor = o.floor;
    p.maxRadius = o.maxRadius;
    p.targetNoise = o.targetNoise;
    p.goodNoise = o.goodNoise;
    p.disagreement = o.disagreement;
    p.k = o.k;
    p.sigmaWeight = o.sigmaWeight;
    p.bilateralRadius = o.bilateralRadius;
    p.sigmaRange = o.sigmaRange;
    return p;
}

}  // namespace mcd::test
