#include "cpu_reference/temporal.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace mcd::ref {

namespace {

constexpr double kAlbedoFloor = 0.05;
constexpr int kHasNormal = 1, kHasDepth = 2, kHasAlbedo = 4, kHasId = 8;

bool Finite(double v) {
    return std::isfinite(v);
}

// Two values agree when equal, or when their difference is finite and within `rel` times
// the larger magnitude (at least `floor`).
bool Within(double a, double b, double rel, double floor) {
    if (a == b) return true;
    double d = a - b;
    return Finite(d) && std::fabs(d) <= rel * std::max({std::fabs(a), std::fabs(b), floor});
}

// Whether the features present (test.features) agree between the current frame's pixel i
// and the neighbour's pixel k; anything NaN disagrees.
bool FeaturesAgree(const Image &cur, size_t i, const Image &nb, size_t k,
                   const TemporalTest &test) {
    auto a = [&](int plane) { return double(cur.Plane(plane)[i]); };
    auto b = [&](int plane) { return double(nb.Plane(plane)[k]); };
    if ((test.features & kHasId) && !(a(7) == b(7))) return false;
    if (test.features & kHasNormal) {
        double dot = 0, la = 0, lb = 0;
        for (int c = 0; c < 3; ++c) {
            dot += a(c) * b(c);
            la += a(c) * a(c);
            lb += b(c) * b(c);
        }
        bool background = la == 0 && lb == 0;
        if (!background && !(dot >= test.normalCos * std::sqrt(la * lb))) return false;
    }
    if ((test.features & kHasDepth) && !Within(a(3), b(3), test.depthRel, 0)) return false;
    if (test.features & kHasAlbedo)
        for (int c = 4; c < 7; ++c)
            if (!Within(a(c), b(c), test.albedoRel, kAlbedoFloor)) return false;
    return true;
}

// A position: float32 coordinates (the layout's numbers).
struct Position {
    float x, y;
};

bool Inside(Position p, int w, int h) {
    return Finite(p.x) && Finite(p.y) && p.x >= 0 && p.y >= 0 && p.x < float(w) &&
           p.y < float(h);
}

size_t PixelOf(Position p, int w) {
    return size_t(std::floor(p.y)) * size_t(w) + size_t(std::floor(p.x));
}

// A frame's motion at pixel k as a step to the frame one further in `direction`: Blender's
// (X, Y) is previous minus here with y up, (Z, W) here minus next.
Position Step(const Image &motion, size_t k, int direction) {
    if (direction < 0) return {motion.Plane(0)[k], -motion.Plane(1)[k]};
    return {-motion.Plane(2)[k], motion.Plane(3)[k]};
}

Position Add(Position p, Position s) {
    return {p.x + s.x, p.y + s.y};
}

// A sample's weight: the frame's spp at k (finite and > 0, else 1), or 1.
double SampleWeight(const Image *spp, size_t k) {
    if (!spp) return 1;
    double s = spp->data[k];
    return Finite(s) && s > 0 ? s : 1;
}

bool ColourFinite(const Image &color, size_t k) {
    for (int c = 0; c < color.channels; ++c)
        if (!Finite(color.Plane(c)[k])) return false;
    return true;
}

// The forward-backward check: the frame's vector at k back towards the chain's previous
// frame lands within tol (each axis) of where the chain came from.
bool MotionConsistent(const Image &motion, size_t k, Position p, Position from, int direction,
                      double tol) {
    Position back = Add(p, Step(motion, k, -direction));
    return std::fabs(double(back.x - from.x)) <= tol &&
           std::fabs(double(back.y - from.y)) <= tol;
}

}  // namespace

TemporalMatched TemporalMatch(const Image &currentFeatures, const Image &features,
                              const Image &color, const Image *spp, const Image *motion,
                              const Image &previous, const Image &position, bool self,
                              bool first, int direction, const TemporalTest &test) {
    int w = color.width, h = color.height;
    TemporalMatched out{Image(w, h, 1), Image(w, h, 2)};
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t i = size_t(y) * w + x;
            Position centre{float(x) + 0.5f, float(y) + 0.5f};
            Position p = self ? centre : Position{position.Plane(0)[i], position.Plane(1)[i]};
            bool geometry = Inside(p, w, h);
            size_t k = geometry ? PixelOf(p, w) : 0;
            if (geometry && !self)
                geometry = FeaturesAgree(currentFeatures, i, features, k, test);
            if (geometry && !self && motion && test.motionTol > 0) {
                Position from =
                    first ? centre : Position{previous.Plane(0)[i], previous.Plane(1)[i]};
                geometry = MotionConsistent(*motion, k, p, from, direction, test.motionTol);
            }
            bool accepted = geometry && ColourFinite(color, k);
            out.weight.data[i] = accepted ? float(SampleWeight(spp, k)) : 0.f;
            Position next = p;
            if (motion)
                next = geometry ? Add(p, Step(*motion, k, direction)) : Position{nan, nan};
            out.next.Plane(0)[i] = next.x;
            out.next.Plane(1)[i] = next.y;
        }
    return out;
}

void TemporalFold(const Image &value, const Image &position, const Image &weight,
                  const Image &total, TemporalFoldMode mode, int power, bool first,
                  bool centres, Image &state) {
    int w = weight.width, h = weight.height;
    int channels = mode == TemporalFoldMode::Count ? 1 : value.channels;
    size_t n = size_t(w) * h;
    for (int c = 0; c < channels; ++c)
        for (size_t i = 0; i < n; ++i) {
            float &a = state.data[c * n + i];
            float *b =
                state.channels > channels ? &state.data[(channels + c) * n + i] : nullptr;
            double wt = weight.data[i];
            double v = 0;
            if (mode != TemporalFoldMode::Count) {
                if (centres)
                    v = value.Plane(c)[i];
                else if (wt > 0)
                    v = value.Plane(
                        c)[PixelOf({position.Plane(0)[i], position.Plane(1)[i]}, w)];
            }
            if (mode == TemporalFoldMode::Min || mode == TemporalFoldMode::Max) {
                if (first) {
                    a = float(v);
                } else if (wt > 0 && Finite(v)) {
                    bool better = mode == TemporalFoldMode::Min ? v < a : v > a;
                    if (!Finite(a) || better) a = float(v);
                }
                continue;
            }
            if (!(wt > 0)) {
                if (first) {
                    a = 0;
                    if (b) *b = 0;
                }
                continue;
            }
            double oldA = first ? 0 : a, oldB = first || !b ? 0 : *b;
            switch (mode) {
                case TemporalFoldMode::Moments: {
                    // The weighted mean of (the folded values, weight W) and (v, wt), and the
                    // squared deviations' sum grown by W wt / (W + wt) (v - mean)^2.
                    double before = first ? 0 : total.data[i];
                    double after = before + wt;
                    a = float((before * oldA + wt * v) / after);
                    // The first value has no deviation (0, even where it is not finite).
                    *b = first ? 0.f
                               : float(oldB + before * wt / after * (v - oldA) * (v - oldA));
                    break;
                }
                case TemporalFoldMode::Sum:
                    a = float(oldA + (power == 0 ? 1.0 : power == 1 ? wt : wt * wt) * v);
                    break;
                case TemporalFoldMode::Count:
                    a = float(oldA + wt);
                    *b = float(oldB + 1);
                    break;
                default:
                    break;
            }
        }
}

Image TemporalFinish(const Image &moments, const Image &counts, const Image *pooled,
                     const Image &raw, const Image *sum0, const Image *counts0,
                     const Image *sum1, const Image *counts1, int fillRadius) {
    int w = raw.width, h = raw.height, C = raw.channels;
    bool halves = sum0 && counts0 && sum1 && counts1;
    Image out(w, h, (halves ? 4 : 2) * C);
    for (int c = 0; c < C; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                size_t i = size_t(y) * w + x;
                double weights = counts.Plane(0)[i], frames = counts.Plane(1)[i];
                double mean = frames > 0 ? moments.Plane(c)[i] : raw.Plane(c)[i];
                out.Plane(c)[i] = float(mean);
                double variance = 0;
                if (weights > 0 && pooled) {
                    variance = pooled->Plane(c)[i] / (weights * weights);
                } else if (weights > 0 && frames >= 2) {
                    variance = moments.Plane(C + c)[i] / ((frames - 1) * weights);
                } else if (weights > 0) {
                    double spread = 0, dof = 0;
                    for (int v = std::max(0, y - fillRadius);
                         v <= std::min(h - 1, y + fillRadius); ++v)
                        for (int u = std::max(0, x - fillRadius);
                             u <= std::min(w - 1, x + fillRadius); ++u) {
                            size_t j = size_t(v) * w + u;
                            if (counts.Plane(1)[j] < 2) continue;
                            spread += moments.Plane(C + c)[j];
                            dof += counts.Plane(1)[j] - 1.0;
                        }
                    variance = dof > 0 ? spread / dof / weights : 0;
                }
                out.Plane(C + c)[i] = float(variance);
                if (!halves) continue;
                double w0 = counts0->Plane(0)[i], w1 = counts1->Plane(0)[i];
                out.Plane(2 * C + c)[i] = w0 > 0 ? float(sum0->Plane(c)[i] / w0) : float(mean);
                out.Plane(3 * C + c)[i] = w1 > 0 ? float(sum1->Plane(c)[i] / w1) : float(mean);
            }
    return out;
}

namespace {

// One accepted sample of a pixel: which frame, its pixel there, its weight and its half.
struct Sample {
    const TemporalFrame *frame;
    size_t k;
    double w;
    int half;
};

// The samples accepted for pixel (x, y): the current frame's, then each side's chain.
std::vector<Sample> Collect(const TemporalFrame &current,
                            const std::vector<const TemporalFrame *> sides[2], int x, int y,
                            const TemporalParams &params, bool withSpp, bool withMotion) {
    int w = current.color->width, h = current.color->height;
    size_t i = size_t(y) * w + x;
    std::vector<Sample> samples;
    if (ColourFinite(*current.color, i))
        samples.push_back({&current, i, SampleWeight(withSpp ? current.spp : nullptr, i), 0});
    TemporalTest test;
    test.normalCos =
        double(float(std::cos(double(params.normalAngle) * std::numbers::pi / 180)));
    test.depthRel = params.depthTolerance;
    test.albedoRel = params.albedoTolerance;
    test.motionTol = params.motionTolerance;
    Position centre{float(x) + 0.5f, float(y) + 0.5f};
    for (int side = 0; side < 2; ++side) {
        int direction = side == 0 ? -1 : 1;
        Position from = centre;
        Position p = withMotion ? Add(centre, Step(*current.motion, i, direction)) : centre;
        for (size_t step = 0; step < sides[side].size(); ++step) {
            const TemporalFrame &f = *sides[side][step];
            if (!Inside(p, w, h)) break;
            size_t k = PixelOf(p, w);
            test.features = current.mask & f.mask;
            bool geometry = FeaturesAgree(current.features, i, f.features, k, test);
            if (geometry && withMotion && test.motionTol > 0)
                geometry = MotionConsistent(*f.motion, k, p, from, direction, test.motionTol);
            if (geometry && ColourFinite(*f.color, k))
                samples.push_back(
                    {&f, k, SampleWeight(withSpp ? f.spp : nullptr, k), int(step + 1) % 2});
            if (!withMotion) continue;  // a still camera: the chain never breaks
            if (!geometry) break;
            from = p;
            p = Add(p, Step(*f.motion, k, direction));
        }
    }
    return samples;
}

// The weighted statistics of one layer's samples at a pixel.
struct Moments {
    double weights = 0, frames = 0, spread = 0, pooled = 0;
    std::vector<double> mean, deviations, pooledSum;
};

// A layer's value of a sample (getLayer(frame) is the frame's image of the layer).
template <class Get>
Moments MomentsOf(const std::vector<Sample> &samples, int channels, Get getLayer,
                  const char *varianceLayer) {
    Moments m;
    m.mean.assign(channels, 0);
    m.deviations.assign(channels, 0);
    m.pooledSum.assign(channels, 0);
    for (const Sample &s : samples) {
        m.weights += s.w;
        m.frames += 1;
    }
    for (int c = 0; c < channels; ++c) {
        double sum = 0;
        for (const Sample &s : samples) sum += s.w * getLayer(*s.frame)->Plane(c)[s.k];
        m.mean[c] = m.weights > 0 ? sum / m.weights : 0;
        for (const Sample &s : samples) {
            double d = getLayer(*s.frame)->Plane(c)[s.k] - m.mean[c];
            m.deviations[c] += s.w * d * d;
            if (varianceLayer)
                m.pooledSum[c] += s.w * s.w * s.frame->layers.at(varianceLayer)->Plane(c)[s.k];
        }
    }
    return m;
}

// A moments layer finished: mean (raw where no sample), variance (pooled, spread, or the
// spread pooled over the window).
void FinishMoments(const std::vector<Moments> &all, const Image &raw, bool pooled,
                   int fillRadius, Image &mean, Image &variance) {
    int w = raw.width, h = raw.height;
    mean = Image(w, h, raw.channels);
    variance = Image(w, h, raw.channels);
    for (int c = 0; c < raw.channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                size_t i = size_t(y) * w + x;
                const Moments &m = all[i];
                mean.Plane(c)[i] = m.frames > 0 ? float(m.mean[c]) : raw.Plane(c)[i];
                double v = 0;
                if (m.weights > 0 && pooled) {
                    v = m.pooledSum[c] / (m.weights * m.weights);
                } else if (m.weights > 0 && m.frames >= 2) {
                    v = m.deviations[c] / ((m.frames - 1) * m.weights);
                } else if (m.weights > 0) {
                    double spread = 0, dof = 0;
                    for (int yy = std::max(0, y - fillRadius);
                         yy <= std::min(h - 1, y + fillRadius); ++yy)
                        for (int xx = std::max(0, x - fillRadius);
                             xx <= std::min(w - 1, x + fillRadius); ++xx) {
                            const Moments &o = all[size_t(yy) * w + xx];
                            if (o.frames < 2) continue;
                            spread += o.deviations[c];
                            dof += o.frames - 1;
                        }
                    v = dof > 0 ? spread / dof / m.weights : 0;
                }
                variance.Plane(c)[i] = float(v);
            }
}

// min, max or hist over the samples, the current frame's own value first (Min/Max).
float Extreme(const std::vector<Sample> &samples, const TemporalFrame &current, size_t i,
              const std::string &name, int c) {
    double a = current.layers.at(name)->Plane(c)[i];
    for (const Sample &s : samples) {
        if (s.frame == &current) continue;
        double v = s.frame->layers.at(name)->Plane(c)[s.k];
        if (!Finite(v)) continue;
        bool better = name == "min" ? v < a : v > a;
        if (!Finite(a) || better) a = v;
    }
    return float(a);
}

}  // namespace

TemporalGatheredRef TemporalGather(const std::vector<TemporalFrame> &frames,
                                   const TemporalParams &params, bool withSpp, bool withMotion,
                                   bool pooled,
                                   const std::map<std::string, bool> &layerPooled) {
    const TemporalFrame *current = nullptr;
    for (const TemporalFrame &f : frames)
        if (f.offset == 0) current = &f;
    std::vector<const TemporalFrame *> sides[2];
    for (int side = 0; side < 2; ++side)
        for (int k = 1; k <= params.radius; ++k) {
            const TemporalFrame *found = nullptr;
            for (const TemporalFrame &f : frames)
                if (f.offset == (side == 0 ? -k : k)) found = &f;
            if (!found) break;
            sides[side].push_back(found);
        }
    const Image &color = *current->color;
    int w = color.width, h = color.height, C = color.channels;
    size_t n = size_t(w) * h;
    std::vector<std::vector<Sample>> samples(n);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            samples[size_t(y) * w + x] =
                Collect(*current, sides, x, y, params, withSpp, withMotion);

    TemporalGatheredRef out;
    std::vector<Moments> moments(n);
    for (size_t i = 0; i < n; ++i)
        moments[i] = MomentsOf(
            samples[i], C, [](const TemporalFrame &f) { return f.color; }, nullptr);
    if (pooled)
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < C; ++c) {
                double v = 0;
                for (const Sample &s : samples[i])
                    v += s.w * s.w * s.frame->variance->Plane(c)[s.k];
                moments[i].pooledSum[c] = v;
            }
    FinishMoments(moments, color, pooled, params.fillRadius, out.layers["color"],
                  out.layers["variance"]);
    Image spp(w, h, 1), count(w, h, 1), halves[2] = {Image(w, h, C), Image(w, h, C)};
    for (size_t i = 0; i < n; ++i) {
        spp.data[i] = float(moments[i].weights);
        count.data[i] = float(moments[i].frames);
        for (int half = 0; half < 2; ++half) {
            double weights = 0;
            std::vector<double> sum(C, 0);
            for (const Sample &s : samples[i])
                if (s.half == half) {
                    weights += s.w;
                    for (int c = 0; c < C; ++c) sum[c] += s.w * s.frame->color->Plane(c)[s.k];
                }
            for (int c = 0; c < C; ++c)
                halves[half].Plane(c)[i] =
                    weights > 0 ? float(sum[c] / weights) : out.layers["color"].Plane(c)[i];
        }
    }
    out.layers["half0.color"] = halves[0];
    out.layers["half1.color"] = halves[1];
    if (withSpp) out.layers["spp"] = spp;
    out.layers["frames"] = count;

    for (const auto &[name, image] : current->layers) {
        if (name == "min" || name == "max" || name == "hist") {
            Image result(w, h, image->channels);
            for (int c = 0; c < image->channels; ++c)
                for (size_t i = 0; i < n; ++i) {
                    if (name != "hist") {
                        result.Plane(c)[i] = Extreme(samples[i], *current, i, name, c);
                        continue;
                    }
                    double sum = 0;
                    for (const Sample &s : samples[i])
                        sum += s.frame->layers.at(name)->Plane(c)[s.k];
                    result.Plane(c)[i] = float(sum);
                }
            out.layers[name] = result;
        } else if (name == "direct" || name == "indirect") {
            bool own = layerPooled.count(name) && layerPooled.at(name);
            std::string variance = name + ".variance";
            std::vector<Moments> m(n);
            for (size_t i = 0; i < n; ++i)
                m[i] = MomentsOf(
                    samples[i], image->channels,
                    [&](const TemporalFrame &f) { return f.layers.at(name); },
                    own ? variance.c_str() : nullptr);
            FinishMoments(m, *image, own, params.fillRadius, out.layers[name],
                          out.layers[variance]);
        }
    }
    return out;
}

}  // namespace mcd::ref
