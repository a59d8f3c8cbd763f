#include "cpu_reference/bayes_model.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "bayes/bayes.h"

namespace mcd::ref {

double GlSecondMoment(double s, double p) {
    return s * s * std::exp(std::lgamma(3 / p) - std::lgamma(1 / p));
}

double GlFourthMoment(double s, double p) {
    return s * s * s * s * std::exp(std::lgamma(5 / p) - std::lgamma(1 / p));
}

double GlKurtosis(double p) {
    return std::exp(std::lgamma(5 / p) + std::lgamma(1 / p) - 2 * std::lgamma(3 / p));
}

BandFit SolveBand(double m2, double m4, int64_t count, double sn, double pn) {
    BandFit result;
    if (count == 0) {
        result.fit = BAYES_FIT_EMPTY;
        return result;
    }
    // Compared in float, as the GPU's band parameters are: the same side of the bound.
    if (float(sn) < float(BAYES_MIN_NOISE_S)) {
        result.fit = BAYES_FIT_NO_NOISE;
        return result;
    }
    double varN = GlSecondMoment(sn, pn), m4N = GlFourthMoment(sn, pn);
    double varC = m2 - varN;
    if (!std::isfinite(m2) || !std::isfinite(m4) ||
        !(varC > BAYES_MIN_SIGNAL_FRACTION * varN)) {
        result.fit = BAYES_FIT_NO_SIGNAL;
        return result;
    }
    double m4C = m4 - m4N - 6 * varC * varN;
    double pc;
    if (!(m4C > 0)) {
        pc = BAYES_P_HI;
        result.fit = BAYES_FIT_P_HIGH;
    } else {
        // Solve log kurtosis(p) = log(m4_c / var_c^2) for p; kurtosis decreases with p.
        double target = std::log(m4C) - 2 * std::log(varC);
        double lo = BAYES_P_LO, hi = BAYES_P_HI;
        if (target >= std::log(GlKurtosis(lo))) {
            pc = lo;
            result.fit = BAYES_FIT_P_LOW;
        } else if (target <= std::log(GlKurtosis(hi))) {
            pc = hi;
            result.fit = BAYES_FIT_P_HIGH;
        } else {
            for (int i = 0; i < 100; ++i) {
                double mid = 0.5 * (lo + hi);
                if (std::log(GlKurtosis(mid)) > target)
                    lo = mid;
                else
                    hi = mid;
            }
            pc = 0.5 * (lo + hi);
            result.fit = BAYES_FIT_SOLVED;
        }
    }
    result.pc = pc;
    result.sc = std::sqrt(varC * std::exp(std::lgamma(1 / pc) - std::lgamma(3 / pc)));
    return result;
}

double PosteriorMean(double y, const BandFit &fit, double sn, double pn) {
    if (fit.fit == BAYES_FIT_NO_NOISE) return y;
    if (fit.fit == BAYES_FIT_NO_SIGNAL || fit.fit == BAYES_FIT_EMPTY) return 0;
    double ay = std::fabs(y);
    if (ay == 0) return 0;  // odd: exactly 0, not the quadrature's round-off
    double sc = fit.sc, pc = fit.pc;
    double a = std::min(sn, sc);
    double noiseWidth = sn * std::pow(BAYES_TAIL, 1 / pn);
    double reach = std::max(noiseWidth, sc * std::pow(BAYES_TAIL, 1 / pc));
    double t0 = std::asinh(-reach / a), t1 = std::asinh((ay + reach) / a);
    double dt = std::min(1 / BAYES_STEPS_PER_WIDTH,
                         sn / (BAYES_STEPS_PER_WIDTH * (ay + noiseWidth + a)));
    double points = std::ceil((t1 - t0) / dt);
    int n = int(std::clamp(points, double(BAYES_MIN_POINTS), double(BAYES_MAX_POINTS)));
    dt = (t1 - t0) / n;
    // Log of integrand times the grid's weight a cosh(t) dt, at each midpoint.
    std::vector<double> logTerm(n), c(n);
    double peak = -INFINITY;
    for (int k = 0; k < n; ++k) {
        double t = t0 + (k + 0.5) * dt;
        c[k] = a * std::sinh(t);
        logTerm[k] = -std::pow(std::fabs(ay - c[k]) / sn, pn) -
                     std::pow(std::fabs(c[k]) / sc, pc) + std::log(a * std::cosh(t) * dt);
        peak = std::max(peak, logTerm[k]);
    }
    double num = 0, den = 0;
    for (int k = 0; k < n; ++k) {
        double w = std::exp(logTerm[k] - peak);
        num += w * c[k];
        den += w;
    }
    double mean = num / den;
    return y < 0 ? -mean : mean;
}

}  // namespace mcd::ref
