// The paper's bayes pipeline (Xu & Pattanaik, section 4): the decimated DWT and the fixed
// noise s_n, where BayesParams' defaults are the measured choices. The tests that check
// the paper's pipeline start from it.
#pragma once

#include "host/methods/bayes.h"

namespace mcd::test {

inline BayesParams PaperBayesParams() {
    BayesParams options;
    options.transform = BayesTransform::Dwt;
    options.noise = BayesNoise::Fixed;
    return options;
}

}  // namespace mcd::test
