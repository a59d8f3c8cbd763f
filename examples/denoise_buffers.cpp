// Denoise a renderer's buffers in memory, no files: denoise_buffers [METHOD]
// A toy renderer fills interleaved float buffers (RGBA color, albedo, normal, the
// variance of the mean) with a Monte Carlo estimate of a known image; the frame borrows
// them, the result goes into the renderer's own RGBA output buffer, alpha passed through.
// Prints the error before and after; fails if the method did not reduce it.
#include <mcdenoise/mcdenoise.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace {

constexpr int kWidth = 96, kHeight = 64, kSpp = 4;

// What the renderer's buffers hold, interleaved [y][x][c].
struct Buffers {
    std::vector<float> color = std::vector<float>(kWidth * kHeight * 4);  // RGBA
    std::vector<float> albedo = std::vector<float>(kWidth * kHeight * 3);
    std::vector<float> normal = std::vector<float>(kWidth * kHeight * 3);
    std::vector<float> variance = std::vector<float>(kWidth * kHeight * 3);
    std::vector<float> truth = std::vector<float>(kWidth * kHeight * 3);  // noise-free
};

// A checkerboard lit by a soft round light, estimated with kSpp samples of exponential
// noise per pixel; alpha is the coverage of a disc.
Buffers Render() {
    Buffers b;
    std::mt19937 rng(7);
    std::exponential_distribution<float> noise(1.f);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            int p = y * kWidth + x;
            bool dark = ((x / 12) + (y / 12)) % 2 == 1;
            float albedo[3] = {dark ? 0.2f : 0.8f, dark ? 0.25f : 0.6f, dark ? 0.3f : 0.4f};
            float dx = x - 0.3f * kWidth, dy = y - 0.4f * kHeight;
            float light = 0.2f + 2.f * std::exp(-(dx * dx + dy * dy) / 600.f);
            float ex = x - 0.5f * kWidth, ey = y - 0.5f * kHeight;
            float alpha = ex * ex + ey * ey < 0.16f * kHeight * kHeight ? 1.f : 0.5f;
            for (int c = 0; c < 3; ++c) {
                float radiance = albedo[c] * light, sum = 0, sumSq = 0;
                for (int s = 0; s < kSpp; ++s) {
                    float sample = radiance * noise(rng);
                    sum += sample;
                    sumSq += sample * sample;
                }
                float mean = sum / kSpp;
                b.color[p * 4 + c] = mean;
                b.variance[p * 3 + c] = (sumSq / kSpp - mean * mean) / (kSpp - 1);
                b.albedo[p * 3 + c] = albedo[c];
                b.normal[p * 3 + c] = c == 2 ? 1.f : 0.f;
                b.truth[p * 3 + c] = radiance;
            }
            b.color[p * 4 + 3] = alpha;
        }
    return b;
}

// relMSE of an RGBA or RGB buffer's colour against the truth.
double RelMse(const std::vector<float> &image, int stride, const std::vector<float> &truth) {
    double sum = 0;
    for (size_t p = 0; p < truth.size() / 3; ++p)
        for (int c = 0; c < 3; ++c) {
            double d = image[p * stride + c] - truth[p * 3 + c], r = truth[p * 3 + c];
            sum += d * d / (r * r + 1e-2);
        }
    return sum / double(truth.size());
}

}  // namespace

int main(int argc, char **argv) {
    Buffers buffers = Render();
    std::vector<float> output(kWidth * kHeight * 4);
    try {
        mcd::Frame frame;  // borrows the buffers: nothing is copied here
        // RGB out of the RGBA buffer (a pixel is 4 floats), then its alpha channel.
        frame.SetLayer("color",
                       mcd::LayerView::Interleaved(buffers.color.data(), kWidth, kHeight, 3,
                                                   mcd::DataType::Float32, 4 * sizeof(float)));
        frame.SetLayer("alpha",
                       mcd::LayerView::Interleaved(buffers.color.data() + 3, kWidth, kHeight, 1,
                                                   mcd::DataType::Float32, 4 * sizeof(float)));
        frame.SetLayer("albedo",
                       mcd::LayerView::Interleaved(buffers.albedo.data(), kWidth, kHeight, 3));
        frame.SetLayer("normal",
                       mcd::LayerView::Interleaved(buffers.normal.data(), kWidth, kHeight, 3));
        frame.SetLayer("variance", mcd::LayerView::Interleaved(buffers.variance.data(), kWidth,
                                                               kHeight, 3));

        mcd::Device device;
        mcd::Method method(argc > 1 ? argv[1] : "auto");
        mcd::RunOptions run;
        run.output = mcd::OutputView::Interleaved(output.data(), kWidth, kHeight, 4);
        mcd::Result result = method.Run(device, frame, run);

        std::printf("%s", result.method.c_str());
        for (size_t i = 0; i < result.candidates.size(); ++i)
            std::printf("%s%s", i == 0 ? " (candidates: " : ", ", result.candidates[i].c_str());
        std::printf("%s on %s, %dx%d, %.1f ms\n", result.candidates.empty() ? "" : ")",
                    device.Name().c_str(), kWidth, kHeight, result.wallMs);
        for (const std::string &line : result.warnings)
            std::fprintf(stderr, "warning: %s\n", line.c_str());
    } catch (const mcd::Error &e) {
        std::fprintf(stderr, "error (%s): %s\n", mcd::ErrorKindName(e.Kind()), e.what());
        return 1;
    }
    double before = RelMse(buffers.color, 4, buffers.truth);
    double after = RelMse(output, 4, buffers.truth);
    bool alphaKept = true;
    for (int p = 0; p < kWidth * kHeight; ++p)
        alphaKept = alphaKept && output[p * 4 + 3] == buffers.color[p * 4 + 3];
    std::printf("relMSE %.4f -> %.4f; alpha %s\n", before, after,
                alphaKept ? "passed through" : "CHANGED");
    return after < before && alphaKept ? 0 : 1;
}
