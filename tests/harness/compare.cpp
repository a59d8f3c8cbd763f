#include "harness/compare.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "host/metrics.h"

namespace mcd::test {

::testing::AssertionResult ImagesMatch(const Image &expected, const Image &actual,
                                       const Image &magnitude, const Tolerance &tolerance,
                                       CompareStats *statsOut) {
    if (!expected.SameShape(actual))
        return ::testing::AssertionFailure() << fmt::format(
                   "shape {}x{}x{} expected, got {}x{}x{}", expected.width, expected.height,
                   expected.channels, actual.width, actual.height, actual.channels);
    bool haveMagnitude = !magnitude.Empty();
    CompareStats stats;
    std::string report;
    int reported = 0;
    for (int c = 0; c < expected.channels; ++c)
        for (int y = 0; y < expected.height; ++y)
            for (int x = 0; x < expected.width; ++x) {
                double e = expected.At(c, y, x), a = actual.At(c, y, x);
                bool bad = false;
                const char *why = "";
                if (std::isfinite(e) != std::isfinite(a)) {
                    bad = true;
                    why = " (finite/non-finite parity)";
                    ++stats.parityMismatches;
                } else if (std::isfinite(e)) {
                    double scale = haveMagnitude ? double(magnitude.At(c, y, x)) : std::fabs(e);
                    double bound = tolerance.absTol + tolerance.relTol * scale;
                    double err = std::fabs(a - e);
                    double ratio = bound > 0 ? err / bound : (err > 0 ? INFINITY : 0);
                    stats.maxErrorRatio = std::max(stats.maxErrorRatio, ratio);
                    bad = err > bound;
                }
                if (bad) {
                    ++stats.mismatches;
                    if (reported++ < 8)
                        report += fmt::format(
                            "\n  (x={}, y={}, c={}) expected {:.9g} actual {:.9g}{}", x, y, c,
                            e, a, why);
                }
            }
    stats.nmse = MeasureDifference(actual, expected).nmse;
    if (statsOut) *statsOut = stats;
    if (stats.mismatches > 0)
        return ::testing::AssertionFailure()
               << fmt::format("{} of {} elements differ ({} non-finite parity), nmse {:.3g}:",
                              stats.mismatches, expected.Size(), stats.parityMismatches,
                              stats.nmse)
               << report;
    if (stats.nmse > tolerance.maxNmse)
        return ::testing::AssertionFailure()
               << fmt::format("nmse {:.3g} above {:.3g}", stats.nmse, tolerance.maxNmse);
    return ::testing::AssertionSuccess();
}

::testing::AssertionResult BitIdentical(const Image &a, const Image &b) {
    if (!a.SameShape(b)) return ::testing::AssertionFailure() << "shapes differ";
    if (std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0)
        return ::testing::AssertionSuccess();
    for (size_t i = 0; i < a.data.size(); ++i)
        if (std::memcmp(&a.data[i], &b.data[i], sizeof(float)) != 0)
            return ::testing::AssertionFailure()
                   << fmt::format("first difference at element {}: {:.9g} vs {:.9g}", i,
                                  a.data[i], b.data[i]);
    return ::testing::AssertionFailure() << "differ";
}

}  // namespace mcd::test
