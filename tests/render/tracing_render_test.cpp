// The renderer's side of Ershov's tracing filter (section 5): the records TracePath hands
// the gather split each sample exactly, the filtered frame keeps the layers consistent,
// bands do not change it, and where the paper says it is unbiased, it is.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cpu_reference/tracing_filter.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "host/kernels/tracing_gather.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

using render::RenderOptions;
using render::Vec3;

const Image &Layer(const render::RenderResult &r, const std::string &name) {
    for (const auto &[n, image] : r.layers)
        if (n == name) return image;
    throw Error("no layer " + name);
}

RenderOptions Traced(int w, int h, int spp, uint64_t seed, int radius, unsigned layers = 0,
                     int partials = 1) {
    RenderOptions o;
    o.width = w, o.height = h, o.spp = spp, o.seed = seed, o.layers = layers;
    o.tracing.enabled = true;
    o.tracing.params.radius = radius;
    o.tracing.partials = partials;
    return o;
}

double RelMse(const Image &x, const Image &r) {
    double sum = 0;
    for (size_t i = 0; i < x.Size(); ++i) {
        double d = x.data[i] - r.data[i];
        sum += d * d / (double(r.data[i]) * r.data[i] + 0.01);
    }
    return sum / x.Size();
}

// color == rest + the partials' own, sample by sample, and own is the picked lobe's weight
// f cos / p times the radiance the record carries (times the mirror prefix's throughput
// for partial 1); a sample without a record owns nothing; partial 1's pdf carries the
// prefix's lobe odds.
TEST(RenderTracing, EachSampleIsRestPlusOwn) {
    int records[2] = {}, absorbed = 0;
    for (int partials : {1, 2})
        for (const char *name :
             {"relief-abc", "double-textured", "glossy-cornell", "cornell"}) {
            render::Scene scene = render::BuildScene(name);
            render::SampleSource source(scene, 16, 16, 5);
            for (int i = 0; i < 2000; ++i) {
                render::TracingPath t;
                t.partials = partials;
                render::PathSample p = source.Trace((i % 37) * 0.43, (i % 41) * 0.39, i, &t);
                ASSERT_EQ(t.partials, partials);
                Vec3 own = t.partial[0].own + t.partial[1].own;
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(p.color[c], t.rest[c] + own[c], 1e-12 * (1 + p.color[c]))
                        << name << " sample " << i;
                if (partials == 1) {
                    EXPECT_FALSE(t.partial[1].hasSurface || t.partial[1].record);
                    EXPECT_TRUE(t.partial[1].own.IsBlack());
                }
                EXPECT_FALSE(t.partial[0].record && t.partial[1].record);
                for (int k = 0; k < partials; ++k) {
                    const render::TracingPartial &a = t.partial[k];
                    if (!a.record) {
                        EXPECT_TRUE(a.own.IsBlack()) << name << " sample " << i;
                        continue;
                    }
                    ++records[k];
                    ASSERT_TRUE(a.hasSurface);
                    EXPECT_GT(a.pdf, 0) << name << " sample " << i;
                    EXPECT_NEAR(Length(a.direction), 1, 1e-12);
                    if (a.radiance.IsBlack()) ++absorbed;
                    // Partial 1: the mirror vertex H before A_1 (back along wo), its weight
                    // and its lobe odds; then A_k's own lobes, found again along -wo.
                    render::Hit hit;
                    Vec3 weight(1);
                    double odds = 1;
                    if (k == 1) {
                        ASSERT_TRUE(
                            scene.Intersect({a.position + a.wo * 1e-5, a.wo}, 1e30, &hit));
                        const render::Material &h = scene.materials[hit.material];
                        weight = h.mirror;
                        odds = h.mirror.MaxComponent() /
                               (scene.Diffuse(h, hit).MaxComponent() +
                                scene.Glossy(h, hit).MaxComponent() + h.mirror.MaxComponent());
                    }
                    ASSERT_TRUE(scene.Intersect({a.position + a.wo * 1e-3, -a.wo}, 1e30, &hit));
                    const render::Material &m = scene.materials[hit.material];
                    Vec3 d = scene.Diffuse(m, hit), g = scene.Glossy(m, hit);
                    double total =
                        d.MaxComponent() + g.MaxComponent() + m.mirror.MaxComponent();
                    for (int c = 0; c < 3; ++c)
                        EXPECT_NEAR(a.diffuse[c], weight[c] * d[c], 1e-9) << name << " " << i;
                    // own = radiance x lobe x total / its max channel x the prefix's throughput
                    // (weight / odds): the diffuse or the glossy lobe matches.
                    bool matched = false;
                    for (const Vec3 &lobe : {d, g}) {
                        if (lobe.MaxComponent() <= 0) continue;
                        bool all = true;
                        for (int c = 0; c < 3; ++c) {
                            double expected = a.radiance[c] * lobe[c] * total /
                                              lobe.MaxComponent() * weight[c] / odds;
                            all =
                                all && std::fabs(a.own[c] - expected) <= 1e-9 * (1 + expected);
                        }
                        matched = matched || all;
                    }
                    EXPECT_TRUE(matched) << name << " partial " << k << " sample " << i;
                }
            }
        }
    std::fprintf(stderr, "[mcd] %d partial-0 records, %d partial-1, %d with no light back\n",
                 records[0], records[1], absorbed);
    EXPECT_GT(records[0], 2000);
    EXPECT_GT(records[1], 50);
}

// Radius 0 leaves every pixel to its own samples: the frame is the plain one bit for bit,
// and so is color.unfiltered with any radius (and the half-buffers with half0's own layers,
// of the samples before the filter); with partial 1 filtered too (glossy-cornell's mirror)
// and without.
TEST(RenderTracing, RadiusZeroIsThePlainFrame) {
    for (auto [sceneName, partials] : {std::pair{"relief-abc", 1}, {"glossy-cornell", 2}}) {
        render::Scene scene = render::BuildScene(sceneName);
        const unsigned layers =
            render::kLayersAll | render::kLayersPartials | render::kLayersHalves;
        RenderOptions plainOptions = Traced(21, 17, 3, 4, 0, layers);
        plainOptions.tracing.enabled = false;
        render::RenderResult plain = render::Render(scene, plainOptions);
        render::RenderResult zero =
            render::Render(scene, Traced(21, 17, 3, 4, 0, layers, partials));
        render::RenderResult four =
            render::Render(scene, Traced(21, 17, 3, 4, 4, layers, partials));
        for (const auto &[name, image] : plain.layers) {
            EXPECT_TRUE(BitIdentical(image, Layer(zero, name))) << sceneName << " " << name;
            bool filtered = name == "color" || name == "indirect" || name == "partial0.color" ||
                            (partials > 1 && name == "partial1.color");
            if (!filtered) {
                EXPECT_TRUE(BitIdentical(image, Layer(four, name))) << sceneName << " " << name;
            }
        }
        EXPECT_TRUE(BitIdentical(Layer(plain, "color"), Layer(zero, "color.unfiltered")));
        EXPECT_TRUE(BitIdentical(Layer(plain, "color"), Layer(four, "color.unfiltered")));
        EXPECT_FALSE(BitIdentical(Layer(plain, "color"), Layer(four, "color")));
        if (partials > 1) {
            EXPECT_FALSE(
                BitIdentical(Layer(plain, "partial1.color"), Layer(four, "partial1.color")));
        }
    }
}

// The filtered part is partial 0's and indirect light: the partials and direct + indirect
// still sum to color.
TEST(RenderTracing, SplitsStillSumToColor) {
    render::Scene scene = render::BuildScene("glossy-cornell");
    for (int partials : {1, 2}) {
        render::RenderResult r = render::Render(
            scene,
            Traced(19, 15, 4, 2, 3, render::kLayersSplit | render::kLayersPartials, partials));
        const Image &color = Layer(r, "color"), &direct = Layer(r, "direct"),
                    &indirect = Layer(r, "indirect"), &p0 = Layer(r, "partial0.color"),
                    &p1 = Layer(r, "partial1.color"), &rem = Layer(r, "remainder");
        for (size_t i = 0; i < color.Size(); ++i) {
            float v = color.data[i];
            EXPECT_NEAR(direct.data[i] + indirect.data[i], v, 1e-5f * (1 + std::fabs(v)));
            EXPECT_NEAR(p0.data[i] + p1.data[i] + rem.data[i], v, 1e-5f * (1 + std::fabs(v)));
        }
    }
}

// Bands of 1, 4 and all rows (odd sizes, radius larger than a band) give the same frame
// bit for bit, and a small budget makes more bands; with partial 1's records too (their
// window slides with partial 0's and counts in the budget).
TEST(RenderTracing, BandsDoNotChangeTheFrame) {
    for (auto [sceneName, partials] :
         {std::pair{"double-textured", 1}, {"glossy-cornell", 2}}) {
        render::Scene scene = render::BuildScene(sceneName);
        RenderOptions o = Traced(23, 13, 3, 9, 5, render::kLayersPartials, partials);
        o.tracing.bandRows = 13;
        render::RenderResult whole = render::Render(scene, o);
        EXPECT_EQ(whole.tracing.bands, 1);
        const size_t rowBytes =
            partials * 23 * (sizeof(TracingSurface) + 3 * sizeof(TracingSample));
        for (int band : {1, 4}) {
            o.tracing.bandRows = band;
            render::RenderResult banded = render::Render(scene, o);
            EXPECT_EQ(banded.tracing.bands, (13 + band - 1) / band);
            ASSERT_EQ(banded.layers.size(), whole.layers.size());
            for (size_t i = 0; i < whole.layers.size(); ++i)
                EXPECT_TRUE(BitIdentical(whole.layers[i].second, banded.layers[i].second))
                    << sceneName << " " << whole.layers[i].first << " in bands of " << band;
            // The window holds a band and the radius above and below it, no more.
            EXPECT_LE(banded.tracing.peakRecordBytes,
                      rowBytes * size_t(std::min(13, band + 10)));
        }
        o.tracing.bandRows = 0;
        o.tracing.memoryBudget = rowBytes * 13;
        render::RenderResult budget = render::Render(scene, o);
        EXPECT_EQ(budget.tracing.bandRows, 3);
        EXPECT_LE(budget.tracing.peakRecordBytes, o.tracing.memoryBudget);
        EXPECT_TRUE(BitIdentical(Layer(whole, "color"), Layer(budget, "color"))) << sceneName;
    }
}

// A checkered plane that emits, under a mirror ceiling, both far wider than the view: the
// light arriving at the plane along u (the plane's emission seen in the mirror, and what
// follows) does not vary over the view, the case of eq. 16's derivation, and has no heavy
// tail (no area light sampled over 1600 m^2). The filter re-weights it for each pixel's
// checker colour and lobes.
// `mirrorView`: the ceiling is lower, partly diffuse (0.2, mirror 0.6: the mirror lobe's
// odds 3/4), and the camera looks up at it, so the checker is seen in the mirror (partial
// 1) and the ceiling's diffuse light is partial 0.
render::Scene UniformlyLit(bool mirrorView = false) {
    render::Scene scene;
    scene.name = "uniformly-lit";
    scene.camera = {{0, 0.6, -0.2}, {0, 0, 0}, {0, 1, 0}, 40};
    if (mirrorView) scene.camera = {{0, 0.3, -0.1}, {0, 0.5, 0}, {0, 1, 0}, 40};
    render::Texture checker{render::Texture::Kind::Checker, Vec3(0.9, 0.7, 0.5),
                            Vec3(0.1, 0.2, 0.3), 400};
    scene.textures.push_back(checker);
    render::Material floor{Vec3(1)};
    floor.diffuseTexture = 0;
    floor.glossy = Vec3(0.3);
    floor.glossyKappa = 20;
    floor.emission = Vec3(1);
    render::Material ceiling{Vec3(mirrorView ? 0.2 : 0)};
    ceiling.mirror = Vec3(0.6);
    scene.materials = {floor, ceiling};
    double height = mirrorView ? 0.5 : 1;
    scene.quads.push_back({{-20, 0, -20}, {0, 0, 40}, {40, 0, 0}, 0, 1});  // faces up
    scene.quads.push_back({{-20, height, -20}, {40, 0, 0}, {0, 0, 40}, 1, 2});
    // Seen in the mirror, the floor is not sampled as a light: the ceiling's diffuse part
    // would take heavy-tailed next-event samples of 1600 m^2. Emission then counts where a
    // path sees it after the camera or a mirror only: the same estimator in every pixel.
    if (!mirrorView) scene.lightQuads = {0};
    return scene;
}

// Per seed, the mean of filtered - unfiltered over the pixels wholly inside bright and
// inside dark squares (per channel); over seeds, those means against their standard
// errors. (Per-pixel z scores are no test here: each pixel's difference is skewed, so its
// mean and its standard error are correlated.) `gather` replaces the reference's.
// `mirrorView`: the checker seen in the mirror, partials 0 and 1 filtered, the squares
// told apart by partial 1's pivot (the chain's 0.6 times the albedo).
std::vector<double> CheckerBias(render::TracingGatherFn gather, int seeds,
                                bool mirrorView = false) {
    render::Scene scene = UniformlyLit(mirrorView);
    const int w = 16, h = 12;
    std::vector<double> sum(6), sumSq(6);
    for (int seed = 1; seed <= seeds; ++seed) {
        RenderOptions o = Traced(w, h, 4, seed, 4,
                                 mirrorView ? render::kLayersPartials : render::kLayersGbuffer);
        o.tracing.params.alpha = 0.01f, o.tracing.params.beta = 0;
        o.tracing.gather = gather;
        if (mirrorView) o.tracing.partials = 2;
        render::RenderResult r = render::Render(scene, o);
        const Image &f = Layer(r, "color"), &u = Layer(r, "color.unfiltered"),
                    &albedo = Layer(r, mirrorView ? "partial1.pivot" : "albedo");
        const float bright = mirrorView ? 0.66f : 1.1f, dark = mirrorView ? 0.3f : 0.5f;
        double classSum[6] = {};
        int count[2] = {};
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Albedo: diffuse texture + glossy 0.3, red 1.2 or 0.4; mixed pixels left out.
                float a = albedo.At(0, y, x);
                int k = a > bright ? 0 : (a < dark ? 1 : -1);
                if (k < 0) continue;
                ++count[k];
                for (int c = 0; c < 3; ++c)
                    classSum[k * 3 + c] += double(f.At(c, y, x)) - u.At(c, y, x);
            }
        EXPECT_GT(count[0], 10);
        EXPECT_GT(count[1], 10);
        for (int k = 0; k < 6; ++k) {
            double m = classSum[k] / count[k / 3];
            sum[k] += m, sumSq[k] += m * m;
        }
    }
    std::vector<double> z(6);
    for (int k = 0; k < 6; ++k) {
        double mean = sum[k] / seeds;
        double se = std::sqrt((sumSq[k] - seeds * mean * mean) / (seeds - 1) / seeds);
        z[k] = mean / se;
    }
    std::fprintf(stderr,
                 "[mcd] bright squares z %.2f %.2f %.2f, dark squares z %.2f %.2f %.2f\n", z[0],
                 z[1], z[2], z[3], z[4], z[5]);
    return z;
}

// Unbiased where the light does not vary: seeded, 6 z scores within 4.
TEST(RenderTracing, UnbiasedWhereTheLightDoesNotVary) {
    for (double z : CheckerBias(nullptr, 32)) EXPECT_LT(std::fabs(z), 4.0);
}

// The same check catches a filter without eq. 14's re-weighting for the pixel's own
// surface: with every surface's lobes set to the frame's mean, light leaks from the
// bright squares into the dark ones.
TEST(RenderTracing, BiasCheckCatchesAFilterWithoutReweighting) {
    auto flat = [](const TracingRecords &records, const TracingParams &params, int y0,
                   int rows) {
        TracingRecords copy = records;
        for (TracingSurface &s : copy.surfaces)
            for (int c = 0; c < 3; ++c) s.diffuse[c] = 0.4f, s.glossy[c] = 0.3f;
        return ref::TracingFilter(copy, params, y0, rows);
    };
    std::vector<double> z = CheckerBias(flat, 12);
    EXPECT_GT(z[3], 4.0);   // dark squares brighter
    EXPECT_LT(z[0], -4.0);  // bright squares darker
}

// Section 8: partial 1 (the checker seen in a mirror that is also a diffuse surface, so
// that the prefix's lobe odds count) filtered on its own records, partial 0 too: unbiased.
TEST(RenderTracing, UnbiasedSeenInAMirror) {
    for (double z : CheckerBias(nullptr, 64, true)) EXPECT_LT(std::fabs(z), 4.0);
}

// And the check sees a partial-1 filter that re-weights with a flat BSDF.
TEST(RenderTracing, MirrorBiasCheckCatchesAFilterWithoutReweighting) {
    auto flat = [](const TracingRecords &records, const TracingParams &params, int y0,
                   int rows) {
        TracingRecords copy = records;
        for (TracingSurface &s : copy.surfaces)
            for (int c = 0; c < 3; ++c) s.diffuse[c] = 0.24f, s.glossy[c] = 0.18f;
        return ref::TracingFilter(copy, params, y0, rows);
    };
    std::vector<double> z = CheckerBias(flat, 12, true);
    EXPECT_GT(z[3], 4.0);  // dark squares brighter (red and green; measured z 26 and 23)
    EXPECT_GT(z[4], 4.0);
}

// Error against a converged render keeps falling as the samples grow (cornell: the other
// scenes' relMSE at this size is ruled by a few fireflies): 4x the samples, relMSE at
// least 2x lower (plain MC: 4x; the filter's bias is small against its noise here), and
// below plain MC's.
TEST(RenderTracing, ErrorFallsWithSamples) {
    render::Scene scene = render::BuildScene("cornell");
    const int w = 24, h = 20;
    RenderOptions ro;
    ro.width = w, ro.height = h, ro.spp = 1024, ro.seed = 1000;
    Image reference = Layer(render::Render(scene, ro), "color");
    double low = 0, high = 0, plainLow = 0;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
        render::RenderResult a = render::Render(scene, Traced(w, h, 4, seed, 4));
        render::RenderResult b = render::Render(scene, Traced(w, h, 16, seed + 50, 4));
        low += RelMse(Layer(a, "color"), reference);
        plainLow += RelMse(Layer(a, "color.unfiltered"), reference);
        high += RelMse(Layer(b, "color"), reference);
    }
    std::fprintf(stderr, "[mcd] relMSE filtered 4 spp %.4g, 16 spp %.4g (plain 4 spp %.4g)\n",
                 low / 3, high / 3, plainLow / 3);
    EXPECT_LT(high, low / 2);
    EXPECT_LT(low, plainLow);  // and it helps
}

TEST(RenderTracing, BadParametersAreRefused) {
    render::Scene scene = render::BuildScene("cornell");
    RenderOptions o = Traced(8, 8, 1, 1, -1);
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] { render::Render(scene, o); }));
    o = Traced(8, 8, 1, 1, 2);
    o.tracing.params.alpha = NAN;
    EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] { render::Render(scene, o); }));
    o = Traced(8, 8, 1, 1, 4);
    o.tracing.maxWindowRows = 8;  // fewer than 1 + 2 * 4
    EXPECT_TRUE(ThrowsError(ErrorKind::OutOfMemory, [&] { render::Render(scene, o); }));
    for (int partials : {0, render::kPartialTypes + 1}) {
        o = Traced(8, 8, 1, 1, 2, 0, partials);
        EXPECT_TRUE(ThrowsError(ErrorKind::InvalidArgument, [&] { render::Render(scene, o); }))
            << partials;
    }
}

// The renderer with the GPU gather: the reference's frame to the kernel's round-off, the
// same frame in bands (4 rows: 5 bands of 17) and twice, for each filtered partial's layer.
class RenderTracingGpu : public GpuTest {
  protected:
    void ExpectMatchesTheReferenceInBands(const char *sceneName, int partials,
                                          std::initializer_list<const char *> names) {
        render::Scene scene = render::BuildScene(sceneName);
        RenderOptions o = Traced(23, 17, 3, 6, 3, render::kLayersPartials, partials);
        render::RenderResult cpu = render::Render(scene, o);
        TracingGather gather(Ctx());
        o.tracing.gather = [&](const TracingRecords &r, const TracingParams &p, int y0,
                               int rows) { return gather.Run(r, p, y0, rows); };
        render::RenderResult gpu = render::Render(scene, o);
        o.tracing.bandRows = 4;
        render::RenderResult banded = render::Render(scene, o);
        EXPECT_EQ(banded.tracing.bands, 5);
        for (const char *name : names) {
            const Image &a = Layer(cpu, name), &b = Layer(gpu, name);
            for (size_t i = 0; i < a.Size(); ++i)
                EXPECT_NEAR(b.data[i], a.data[i], 1e-4f * (1 + std::fabs(a.data[i])))
                    << name << i;
            EXPECT_TRUE(BitIdentical(b, Layer(banded, name))) << name;
        }
        EXPECT_TRUE(
            BitIdentical(Layer(gpu, "color"), Layer(render::Render(scene, o), "color")));
    }
};

TEST_F(RenderTracingGpu, MatchesTheReferenceInBands) {
    ExpectMatchesTheReferenceInBands("relief-abc", 1, {"color", "partial0.color"});
}

// Partial 1 filtered too (glossy-cornell's mirror), each partial's gather on the GPU.
TEST_F(RenderTracingGpu, PartialsMatchTheReferenceInBands) {
    ExpectMatchesTheReferenceInBands("glossy-cornell", 2,
                                     {"color", "partial0.color", "partial1.color"});
}

}  // namespace
}  // namespace mcd::test
