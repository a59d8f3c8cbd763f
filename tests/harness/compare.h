// Kernel-vs-reference comparison: non-finite parity first, then a per-element bound
// |actual - expected| <= absTol + relTol * scale (scale from the reference's magnitude
// twin: sum |tap| |x| over the support), then normalised MSE. Reports the first
// mismatches as (x, y, c, expected, actual).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "host/image.h"

namespace mcd::test {

struct Tolerance {
    double relTol = 0;  // times the magnitude image (or |expected| without one)
    double absTol = 0;
    double maxNmse = 1e-10;
};

struct CompareStats {
    size_t mismatches = 0;
    size_t parityMismatches = 0;
    double maxErrorRatio = 0;  // max over elements of |err| / (absTol + relTol * scale)
    double nmse = 0;
};

// `magnitude` may be empty: then |expected| is the scale.
::testing::AssertionResult ImagesMatch(const Image &expected, const Image &actual,
                                       const Image &magnitude, const Tolerance &tolerance,
                                       CompareStats *stats = nullptr);

// Bit-for-bit equality (NaN payloads included).
::testing::AssertionResult BitIdentical(const Image &a, const Image &b);

}  // namespace mcd::test
