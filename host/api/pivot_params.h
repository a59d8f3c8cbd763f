// The CPU reference's parameters for the GPU pipeline's options: the pivot front end's
// Reference() and the pivot tests map them the same way (a mapping, not an algorithm).
#pragma once

#include "cpu_reference/pivot_filter.h"
#include "host/methods/pivot.h"

namespace mcd::api {

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
    p.bilateral = o.filter == PivotFilter::Bilateral;
    return p;
}

}  // namespace mcd::api
