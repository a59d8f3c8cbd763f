#include "cpu_reference/bayes_denoise.h"

#include <algorithm>
#include <cmath>

#include <limits>
#include <utility>

#include "cpu_reference/local_mean.h"
#include "cpu_reference/wavelet_analyze.h"
#include "cpu_reference/wavelet_sqanalyze.h"
#include "cpu_reference/wavelet_swt.h"
#include "cpu_reference/wavelet_synthesize.h"
#include "host/error.h"
#include "wavelet/swt.h"

namespace mcd::ref {

std::vector<double> BayesFloors(const Image &color, double floorRel) {
    std::vector<double> floors(color.channels);
    for (int c = 0; c < color.channels; ++c) {
        std::vector<double> positive;
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double v = color.At(c, y, x);
                if (std::isfinite(v) && v > 0) positive.push_back(v);
            }
        std::sort(positive.begin(), positive.end());
        double median = positive.empty() ? 1.0 : positive[positive.size() / 2];
        // Rounded to float as the kernels hold it, so that a value at the floor is dark alike.
        floors[c] = float(std::max(floorRel * median, 1e-30));
    }
    return floors;
}

namespace {

// Whether channel c at (x, y), clamped to the frame, is black: not finite positive.
bool BlackAt(const Image &image, int c, int y, int x) {
    y = std::clamp(y, 0, image.height - 1), x = std::clamp(x, 0, image.width - 1);
    float v = image.At(c, y, x);
    return !(std::isfinite(v) && v > 0);
}

// Whether (x, y) lies inside black or on a black line in channel c: some pair of opposite
// 3x3 neighbours both black in c.
bool InsideBlack(const Image &image, int c, int y, int x) {
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}})
        if (BlackAt(image, c, y + dy, x + dx) && BlackAt(image, c, y - dy, x - dx)) return true;
    return false;
}

// Whether the pixel at (x, y), clamped to the frame, is dark: no channel finite and above its
// floor.
bool DarkPixel(const Image &image, const std::vector<double> &floors, int y, int x) {
    y = std::clamp(y, 0, image.height - 1), x = std::clamp(x, 0, image.width - 1);
    for (int c = 0; c < image.channels; ++c) {
        double v = image.At(c, y, x);
        if (std::isfinite(v) && v > floors[c]) return false;
    }
    return true;
}

// The mean of log(max(v, floor)) over the in-frame 3x3 neighbour pixels that are not dark,
// log(floor) when none is.
double MissedSampleLog(const Image &image, const std::vector<double> &floors, int c, int y,
                       int x) {
    double sum = 0;
    int count = 0;
    for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, image.height - 1); ++ny)
        for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, image.width - 1); ++nx) {
            if ((nx == x && ny == y) || DarkPixel(image, floors, ny, nx)) continue;
            double v = image.At(c, ny, nx);
            sum += std::log(std::isfinite(v) && v > floors[c] ? v : floors[c]), ++count;
        }
    return count ? sum / count : std::log(floors[c]);
}

// Whether both neighbour pixels of (x, y) along a row, column or diagonal are dark.
bool InsideDark(const Image &image, const std::vector<double> &floors, int y, int x) {
    for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}})
        if (DarkPixel(image, floors, y + dy, x + dx) &&
            DarkPixel(image, floors, y - dy, x - dx))
            return true;
    return false;
}

}  // namespace

Image BayesLog(const Image &color, const std::vector<double> &floors, bool fillMissed) {
    Image out(color.width, color.height, color.channels);
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double v = color.At(c, y, x);
                bool usable = std::isfinite(v) && v > floors[c];
                bool missed = fillMissed && std::isfinite(v) && v >= 0 &&
                              DarkPixel(color, floors, y, x) &&
                              !InsideDark(color, floors, y, x);
                out.At(c, y, x) = missed ? float(MissedSampleLog(color, floors, c, y, x))
                                         : float(std::log(usable ? v : floors[c]));
            }
    return out;
}

Image BayesExp(const Image &logImage, const Image &original, bool restoreZeros) {
    Image out(logImage.width, logImage.height, logImage.channels);
    for (int c = 0; c < out.channels; ++c)
        for (int y = 0; y < out.height; ++y)
            for (int x = 0; x < out.width; ++x) {
                double v = original.At(c, y, x);
                double z = std::clamp(double(logImage.At(c, y, x)), -87.0, 88.0);
                bool black = restoreZeros && v == 0 && InsideBlack(original, c, y, x);
                bool keep = std::isfinite(v) && (v > 0 || (v == 0 && !black));
                out.At(c, y, x) = keep ? float(std::exp(z)) : 0.f;
            }
    return out;
}

std::vector<BayesBand> BayesBands(int width, int height, int channels, int levels) {
    std::vector<BayesBand> bands;
    for (int c = 0; c < channels; ++c)
        for (int level = 0; level < levels; ++level) {
            int w = LevelExtent(width, level), h = LevelExtent(height, level);
            int lowW = (w + 1) / 2, lowH = (h + 1) / 2;
            bands.push_back({c, level, 0, lowW, 0, w, lowH});  // HL: high in x
            bands.push_back({c, level, 1, 0, lowH, lowW, h});  // LH: high in y
            bands.push_back({c, level, 2, lowW, lowH, w, h});  // HH
        }
    return bands;
}

std::vector<BayesBand> BayesSwtBands(int width, int height, int channels, int levels) {
    std::vector<BayesBand> bands;
    for (int c = 0; c < channels; ++c)
        for (int level = 0; level < levels; ++level) {
            bool tx = SwtAxisTransformed(width, level);
            bool ty = SwtAxisTransformed(height, level);
            for (int o = 0; o < 3; ++o) {
                bool used = o == 0 ? tx : (o == 1 ? ty : tx && ty);
                int plane =
                    c * shader::SwtPlaneCount(levels) + shader::SwtDetailPlane(level, o);
                bands.push_back({plane, level, o, 0, 0, used ? width : 0, height});
            }
        }
    return bands;
}

BandMoments MeasureBand(const Image &coefficients, const BayesBand &band) {
    BandMoments m;
    for (int y = band.y0; y < band.y1; ++y)
        for (int x = band.x0; x < band.x1; ++x) {
            double v = coefficients.At(band.channel, y, x);
            m.m2 += v * v;
            m.m4 += v * v * v * v;
            m.maxAbs = std::max(m.maxAbs, std::fabs(v));
            ++m.count;
        }
    if (m.count > 0) m.m2 /= double(m.count), m.m4 /= double(m.count);
    return m;
}

double BandNoiseS(int level, double sn, double hpFactor) {
    return level == 0 ? hpFactor * sn : sn;
}

Image BayesShrinkDirect(const Image &coefficients, const std::vector<BayesBand> &bands,
                        const std::vector<BandFit> &fits, const std::vector<double> &bandSn,
                        double pn) {
    Image out = coefficients;
    for (size_t b = 0; b < bands.size(); ++b) {
        const BayesBand &band = bands[b];
        for (int y = band.y0; y < band.y1; ++y)
            for (int x = band.x0; x < band.x1; ++x)
                out.At(band.channel, y, x) = float(
                    PosteriorMean(coefficients.At(band.channel, y, x), fits[b], bandSn[b], pn));
    }
    return out;
}

namespace {

// Scale each output channel by (sum of the input's finite values >= 0) / (sum of the
// output), in double; a channel whose output sums to 0 is left as is.
void KeepMean(const Image &color, BayesRefResult *result, bool keepStage) {
    Image &out = result->image;
    for (int c = 0; c < color.channels; ++c) {
        double in = 0, sum = 0;
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double v = color.At(c, y, x);
                if (std::isfinite(v) && v >= 0) in += v;
                sum += out.At(c, y, x);
            }
        double scale = sum > 0 ? in / sum : 1.0;
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x)
                out.At(c, y, x) = float(out.At(c, y, x) * scale);
    }
    if (keepStage) result->stages.push_back({"keep mean", out});
}

// Where an input value is above the largest of its 8 neighbours (those inside the frame) in
// its channel, an output above it takes the input's value: a lone peak is never raised.
void CapLonePeaks(const Image &color, Image *out) {
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double around = -std::numeric_limits<double>::infinity();
                for (int v = std::max(y - 1, 0); v <= std::min(y + 1, color.height - 1); ++v)
                    for (int u = std::max(x - 1, 0); u <= std::min(x + 1, color.width - 1); ++u)
                        if (u != x || v != y) {
                            double n = color.At(c, v, u);
                            around = std::isnan(n) ? std::numeric_limits<double>::infinity()
                                                   : std::max(around, n);
                        }
                double in = color.At(c, y, x);
                if (std::isfinite(in) && in > around && out->At(c, y, x) > in)
                    out->At(c, y, x) = float(in);
            }
}

// keepMean, then the local mean.
void RestoreMeans(const Image &color, const BayesParams &params, bool keepStages,
                  const Image *variance, BayesRefResult *result) {
    if (params.keepMean) KeepMean(color, result, keepStages);
    if (params.meanRadius <= 0) return;
    // Kept: the zeros restored black (0 in and out) only, not a filtered value that lands
    // on its input.
    std::vector<bool> kept(color.data.size());
    for (size_t i = 0; i < kept.size(); ++i)
        kept[i] = color.data[i] == 0 && result->image.data[i] == 0;
    RestoreLocalMeans(color, params.meanRadius, &result->image, variance, -1, false, &kept);
    if (keepStages) result->stages.push_back({"local mean", result->image});
}

}  // namespace

std::vector<double> BayesVarianceNoise(const Image &color, const Image &variance,
                                       const std::vector<double> &floors, WaveletBasis basis,
                                       int levels, double pn, bool opponent, bool swt) {
    if (!variance.SameShape(color))
        throw Error("bayes reference: variance shape differs", ErrorKind::InvalidArgument);
    Image perPixel(color.width, color.height, color.channels);
    for (int c = 0; c < color.channels; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double v = variance.At(c, y, x), value = color.At(c, y, x);
                if (std::isnan(v) || v < 0) v = 0;
                if (std::isinf(v)) v = std::numeric_limits<float>::max();
                double mean = std::isfinite(value) ? std::max(value, floors[c]) : floors[c];
                perPixel.At(c, y, x) = float(std::log1p(v / (mean * mean)));
            }
    Image coefVar = swt ? WaveletSwtSqAnalyze(perPixel, basis, levels)
                        : WaveletSqAnalyze(perPixel, basis, levels);
    double shape = std::sqrt(std::exp(std::lgamma(1 / pn) - std::lgamma(3 / pn)));
    std::vector<BayesBand> bands =
        swt ? BayesSwtBands(color.width, color.height, color.channels, levels)
            : BayesBands(color.width, color.height, color.channels, levels);
    std::vector<double> var(bands.size(), 0.0);
    for (size_t b = 0; b < bands.size(); ++b) {
        const BayesBand &band = bands[b];
        int64_t n = int64_t(band.x1 - band.x0) * (band.y1 - band.y0);
        for (int y = band.y0; y < band.y1; ++y)
            for (int x = band.x0; x < band.x1; ++x) var[b] += coefVar.At(band.channel, y, x);
        if (n > 0) var[b] /= double(n);
    }
    if (opponent) {
        // Bands of channel c are at c * (3 levels) + k.
        size_t per = size_t(3 * levels);
        for (size_t k = 0; k < per; ++k) {
            double sum = 0;
            for (int c = 0; c < color.channels; ++c) sum += var[c * per + k];
            for (int c = 0; c < color.channels; ++c) var[c * per + k] = sum / color.channels;
        }
    }
    std::vector<double> s;
    for (double v : var) s.push_back(std::sqrt(std::max(v, 0.0)) * shape);
    return s;
}

namespace {

// One run of the method without cycle spinning.
BayesRefResult BayesDenoiseOnce(const Image &color, const BayesParams &options,
                                const BayesRefRun &run) {
    const bool swt = options.transform == BayesTransform::Swt;
    const double pn = options.pn;
    BayesRefResult result;
    auto stage = [&](const char *name, const Image &image) {
        if (run.keepStages) result.stages.push_back({name, image});
    };
    int levels = std::min(options.levels, MaxWaveletLevels(color.width, color.height));
    std::vector<double> floors = BayesFloors(color, double(options.floorRel));
    Image logImage = BayesLog(color, floors, options.restoreZeros);
    stage("log", logImage);
    // Opponent colour: L = (r+g+b)/sqrt3, C1 = (r-g)/sqrt2, C2 = (r+g-2b)/sqrt6 of the logs.
    const double k3 = 1 / std::sqrt(3.0), k2 = 1 / std::sqrt(2.0), k6 = 1 / std::sqrt(6.0);
    const double opp[3][3] = {{k3, k3, k3}, {k2, -k2, 0}, {k6, k6, -2 * k6}};
    auto mix = [&](Image &image, bool inverse) {
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                double v[3], o[3] = {0, 0, 0};
                for (int c = 0; c < 3; ++c) v[c] = image.At(c, y, x);
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        o[i] += (inverse ? opp[j][i] : opp[i][j]) * v[j];
                for (int c = 0; c < 3; ++c) image.At(c, y, x) = float(o[c]);
            }
    };
    if (levels == 0) {
        // A 1x1 image: no detail band, log then exp.
        result.image = BayesExp(logImage, color, options.restoreZeros);
        stage("exp", result.image);
        RestoreMeans(color, options, run.keepStages, run.variance, &result);
        return result;
    }
    if (options.opponent) {
        mix(logImage, false);
        stage("opponent", logImage);
    }
    Image coefficients = swt ? WaveletSwtAnalyze(logImage, options.basis, levels)
                             : WaveletAnalyze(logImage, options.basis, levels);
    stage("analysis", coefficients);
    std::vector<BayesBand> bands =
        swt ? BayesSwtBands(color.width, color.height, color.channels, levels)
            : BayesBands(color.width, color.height, color.channels, levels);
    std::vector<double> bandSn;
    // run.variance and run.madSn as BayesDenoise resolved them.
    double snBase = run.madSn >= 0 ? run.madSn : options.sn;
    std::vector<double> varianceSn;
    if (run.variance)
        varianceSn = BayesVarianceNoise(color, *run.variance, floors, options.basis, levels, pn,
                                        options.opponent, swt);
    for (const BayesBand &band : bands) {
        BandMoments m = MeasureBand(coefficients, band);
        double sn = run.variance ? varianceSn[bandSn.size()]
                                 : BandNoiseS(band.level, snBase, options.hpFactor);
        result.moments.push_back(m);
        result.fits.push_back(SolveBand(m.m2, m.m4, m.count, sn, pn));
        bandSn.push_back(sn);
    }
    if (run.keepStages) {
        int n = int(bands.size());
        Image moments(4, n, 1), fits(3, n, 1);
        for (int b = 0; b < n; ++b) {
            const BandMoments &m = result.moments[b];
            const BandFit &f = result.fits[b];
            double row[4] = {m.m2, m.m4, m.maxAbs, double(m.count)};
            for (int i = 0; i < 4; ++i) moments.At(0, b, i) = float(row[i]);
            double fit[3] = {f.sc, f.pc, double(f.fit)};
            for (int i = 0; i < 3; ++i) fits.At(0, b, i) = float(fit[i]);
        }
        stage("moments", moments);
        stage("fits", fits);
    }
    Image shrunk = BayesShrinkDirect(coefficients, bands, result.fits, bandSn, pn);
    stage("shrinkage", shrunk);
    Image back = swt ? WaveletSwtSynthesize(shrunk, options.basis, levels)
                     : WaveletSynthesize(shrunk, options.basis, levels);
    stage("synthesis", back);
    if (options.opponent) {
        mix(back, true);
        stage("opponent inverse", back);
    }
    result.image = BayesExp(back, color, options.restoreZeros);
    stage("exp", result.image);
    RestoreMeans(color, options, run.keepStages, run.variance, &result);
    return result;
}

// Cycle spinning: the mean over the shifts; moments, fits and stages of the unshifted run.
BayesRefResult BayesDenoiseSpun(const Image &color, const BayesParams &params,
                                const BayesRefRun &run) {
    BayesParams once = params;
    once.spins = 1;
    once.keepMean = false;  // applied once, to the mean over the shifts
    once.meanRadius = 0;
    int w = color.width, h = color.height, n = params.spins;
    BayesRefResult result = BayesDenoiseOnce(color, once, run);
    BayesRefRun shifted = run;
    shifted.keepStages = false;
    Image sum(w, h, color.channels);
    std::vector<double> acc(color.Size(), 0.0);
    for (int dy = 0; dy < n; ++dy)
        for (int dx = 0; dx < n; ++dx) {
            // Pad dx columns and dy rows at the top left, mirrored: position -k-1 reads k
            // (clamped to the image for images narrower than the shift).
            Image padded(w + dx, h + dy, color.channels);
            for (int c = 0; c < color.channels; ++c)
                for (int y = 0; y < h + dy; ++y)
                    for (int x = 0; x < w + dx; ++x) {
                        int sx = x - dx < 0 ? std::min(dx - x - 1, w - 1) : x - dx;
                        int sy = y - dy < 0 ? std::min(dy - y - 1, h - 1) : y - dy;
                        padded.At(c, y, x) = color.At(c, sy, sx);
                    }
            Image paddedVariance;
            if (run.variance) {
                paddedVariance = Image(w + dx, h + dy, color.channels);
                for (int c = 0; c < color.channels; ++c)
                    for (int y = 0; y < h + dy; ++y)
                        for (int x = 0; x < w + dx; ++x) {
                            int sx = x - dx < 0 ? std::min(dx - x - 1, w - 1) : x - dx;
                            int sy = y - dy < 0 ? std::min(dy - y - 1, h - 1) : y - dy;
                            paddedVariance.At(c, y, x) = run.variance->At(c, sy, sx);
                        }
                shifted.variance = &paddedVariance;
            }
            Image one = BayesDenoiseOnce(padded, once, shifted).image;
            size_t i = 0;
            for (int c = 0; c < color.channels; ++c)
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) acc[i++] += one.At(c, y + dy, x + dx);
        }
    for (size_t i = 0; i < acc.size(); ++i) sum.data[i] = float(acc[i] / (n * n));
    result.image = sum;
    if (run.keepStages) result.stages.push_back({"cycle spinning", result.image});
    RestoreMeans(color, params, run.keepStages, run.variance, &result);
    return result;
}

}  // namespace

BayesRefResult BayesDenoise(const Image &color, const BayesParams &params,
                            const BayesRefRun &run) {
    // The noise source: the variance for --noise variance (and auto given one), the GPU's
    // estimate for mad (and auto without), else sn.
    BayesRefRun resolved = run;
    bool readsVariance =
        params.noise == BayesNoise::Variance || params.noise == BayesNoise::Auto;
    if (params.noise == BayesNoise::Variance && !run.variance)
        throw Error("bayes reference: --noise variance needs the variance",
                    ErrorKind::MissingLayer);
    if (!readsVariance) resolved.variance = nullptr;
    bool mad = !resolved.variance &&
               (params.noise == BayesNoise::Mad || params.noise == BayesNoise::Auto);
    if (mad && run.madSn < 0)
        throw Error("bayes reference: --noise mad needs the GPU run's estimate (madSn)",
                    ErrorKind::Internal);
    if (!mad) resolved.madSn = -1;
    BayesRefResult result = params.spins > 1 ? BayesDenoiseSpun(color, params, resolved)
                                             : BayesDenoiseOnce(color, params, resolved);
    // Once, on the final output: after the restore, and after the average over the shifts.
    CapLonePeaks(color, &result.image);
    return result;
}

}  // namespace mcd::ref
