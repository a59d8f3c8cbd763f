// nfor's options as its CPU twin's parameters: the one mapping that the API's reference run
// (`mcdenoise diff`) and the tests diffing the GPU path against the twin both use, so an
// option cannot reach the GPU path and miss the twin.

#pragma once

#include <vector>

#include "cpu_reference/nfor.h"
#include "host/methods/nfor.h"

namespace mcd::api {

// `featureWeights`: one per feature plane, as NforFeatures gives them for `o`.
ref::NforParams NforReferenceParams(const NforOptions &o,
                                    const std::vector<float> &featureWeights);

}  // namespace mcd::api
