#include "harness/inputs.h"

#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include <fmt/format.h>

namespace mcd::test {

const char *InputKindName(InputKind kind) {
    switch (kind) {
        case InputKind::Uniform:
            return "uniform";
        case InputKind::LogNormalFireflies:
            return "lognormal_fireflies";
        case InputKind::Constant:
            return "constant";
        case InputKind::Impulse:
            return "impulse";
        case InputKind::NonFinite:
            return "nonfinite";
    }
    return "?";
}

uint64_t SeedFromName(std::string_view name) {
    // FNV-1a: stable across runs, platforms and compilers.
    uint64_t h = 1469598103934665603ull;
    for (char c : name) {
        h ^= uint8_t(c);
        h *= 1099511628211ull;
    }
    return h;
}

Image MakeInput(InputKind kind, int width, int height, int channels, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uniform(-1.f, 1.f);
    std::normal_distribution<float> normal(0.f, 1.f);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    Image image(width, height, channels);
    switch (kind) {
        case InputKind::Uniform:
            for (float &v : image.data) v = uniform(rng);
            break;
        case InputKind::LogNormalFireflies:
            for (float &v : image.data) {
                v = std::exp(normal(rng));
                if (unit(rng) < 0.01f) v *= 1e4f;
            }
            break;
        case InputKind::Constant: {
            float value = 0.5f + unit(rng);
            for (float &v : image.data) v = value;
            break;
        }
        case InputKind::Impulse:
            for (int c = 0; c < channels; ++c) {
                int x = int(rng() % uint64_t(width)), y = int(rng() % uint64_t(height));
                image.At(c, y, x) = 1.f + unit(rng);
            }
            break;
        case InputKind::NonFinite: {
            const float specials[3] = {std::numeric_limits<float>::quiet_NaN(),
                                       std::numeric_limits<float>::infinity(),
                                       -std::numeric_limits<float>::infinity()};
            for (float &v : image.data) v = uniform(rng);
            // A few specials, at least one, so small images get one too.
            size_t count = 1 + image.Size() / 97;
            for (size_t i = 0; i < count; ++i)
                image.data[rng() % image.Size()] = specials[rng() % 3];
            break;
        }
    }
    return image;
}

Image MakeVarianceInput(InputKind kind, int width, int height, int channels, uint64_t seed) {
    Image image = MakeInput(kind, width, height, channels, seed);
    for (float &v : image.data)
        if (std::isfinite(v)) v = std::fabs(v);
    return image;
}

Image NoisyPicture(int w, int h, uint64_t seed, double noise) {
    Image image(w, h, 3);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0, 1);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                double clean = 0.4 + 0.5 * (x > w / 2) + 0.3 * std::sin(0.3 * y + c);
                image.At(c, y, x) = float(clean * std::exp(noise * normal(rng)));
            }
    return image;
}

Image LogNormalNoise(int w, int h, uint64_t seed, double sigma) {
    Image noise(w, h, 3);
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> normal(0.f, float(sigma));
    for (float &v : noise.data) v = std::exp(normal(rng));
    return noise;
}

std::vector<KernelShape> KernelShapes() {
    std::vector<KernelShape> cases;
    for (auto [w, h] : {std::pair{37, 23}, std::pair{1, 1}, std::pair{1, 9}, std::pair{13, 1}})
        for (InputKind kind : {InputKind::Uniform, InputKind::LogNormalFireflies,
                               InputKind::Constant, InputKind::NonFinite})
            cases.push_back({w, h, w == 37 ? 3 : 1, kind});
    return cases;
}

std::string KernelShapeName(const ::testing::TestParamInfo<KernelShape> &info) {
    const KernelShape &c = info.param;
    return fmt::format("{}x{}x{}_{}", c.w, c.h, c.channels, InputKindName(c.kind));
}

std::vector<float> Transposed(const std::vector<float> &in, int w, int h) {
    std::vector<float> out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) out[size_t(x) * h + y] = in[size_t(y) * w + x];
    return out;
}

}  // namespace mcd::test
