// Constants shared by the auto kernels (per-pixel combination of candidate denoisers) and
// their host code. The CPU reference (cpu_reference/auto_combine.cpp) keeps its own copies.
#ifndef MCD_SHADERS_AUTO_AUTO_H
#define MCD_SHADERS_AUTO_AUTO_H

#define AUTO_LOCAL_SIZE 64
// Candidates one combination takes at most.
#define AUTO_MAX_CANDIDATES 11
// relMSE's offset: the error of a value is (x - r)^2 / (r^2 + AUTO_REL_OFFSET).
#define AUTO_REL_OFFSET 0.01
// Combination modes.
#define AUTO_MODE_WEIGHTS 0
#define AUTO_MODE_SELECT 1
// Weights, and where every usable estimate is under the floor (all weights equal: the
// estimates tell nothing there) the per-channel median of the usable candidates.
#define AUTO_MODE_WEIGHTS_MEDIAN 2
// Weights, each candidate standing for the unknown reference with its weight, and the
// output the value that minimises the expected relative squared error (relMSE) under
// them; equal weights where every usable estimate is under the floor or the noise
// outweighs what the estimates resolve (shaders/auto/combine.h).
#define AUTO_MODE_RELATIVE 3

#endif
