// The paper's bayes pipeline (Xu & Pattanaik, section 4): the decimated DWT, the fixed
// noise s_n, exact zeros kept and no local mean restored, where BayesParams' defaults are the
// measured choices. The tests that check the paper's pipeline start from it.
#pragma once

#include "host/methods/bayes.h"

namespace mcd::test {

inline BayesParams PaperBayesParams() {
    BayesParams options;
    options.transform = BayesTransform::Dwt;
    options.noise = BayesNoise::Fixed;
    options.restoreZeros = true;  // the paper's black stays black
    options.meanRadius = 0;       // no local mean restored
    return options;
}

}  // namespace mcd::test
