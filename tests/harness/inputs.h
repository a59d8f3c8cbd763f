// Seeded test inputs. A case's seed is a hash of its name, so a failure replays.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "host/image.h"

namespace mcd::test {

enum class InputKind {
    Uniform,             // U[-1, 1)
    LogNormalFireflies,  // exp(N(0,1)) with 1% spikes of 1e4x
    Constant,            // one value everywhere
    Impulse,             // zero but one pixel per channel
    NonFinite,           // uniform laced with NaN, +Inf and -Inf
};

const char *InputKindName(InputKind kind);
uint64_t SeedFromName(std::string_view name);
Image MakeInput(InputKind kind, int width, int height, int channels, uint64_t seed);
// Non-negative inputs (variances): the same kinds, made positive.
Image MakeVarianceInput(InputKind kind, int width, int height, int channels, uint64_t seed);

// An RGB picture (a step and smooth stripes) times multiplicative log-normal noise of
// log-std `noise`: the case method bayes's model is for.
Image NoisyPicture(int w, int h, uint64_t seed, double noise);

// Pure multiplicative noise: RGB exp(N(0, sigma^2)) per value, nothing else.
Image LogNormalNoise(int w, int h, uint64_t seed, double sigma);

// A kernel case's shape and values: odd sizes down to 1x1 and single rows and columns (the
// 37x23 case with 3 channels), each with uniform, firefly, constant and non-finite values.
struct KernelShape {
    int w, h, channels;
    InputKind kind;
};

std::vector<KernelShape> KernelShapes();

// "37x23x3_uniform": a gtest parameter's name.
std::string KernelShapeName(const ::testing::TestParamInfo<KernelShape> &info);

// The w x h plane transposed (h x w): a column pass checked as a row pass.
std::vector<float> Transposed(const std::vector<float> &in, int w, int h);

}  // namespace mcd::test
