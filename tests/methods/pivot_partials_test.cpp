// Ershov section 8 in the renderer and in method `pivot`: the partial images per mirror
// prefix (partial<k>.color, partial<k>.pivot, remainder) add up to the frame, and a frame
// with partials is filtered partial by partial against each partial's own pivot.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "cpu_reference/pivot_filter.h"
#include "harness/compare.h"
#include "harness/errors.h"
#include "harness/gpu_fixture.h"
#include "host/methods/pivot.h"
#include "tools/render/renderer.h"

namespace mcd::test {
namespace {

constexpr double kUnitRoundoff = 0x1p-24;

const Image &Layer(const render::RenderResult &r, const std::string &name) {
    for (const auto &[n, image] : r.layers)
        if (n == name) return image;
    throw Error("no layer " + name);
}

render::RenderResult RenderGlossy(int w, int h, int spp, unsigned layers) {
    static const render::Scene scene = render::BuildScene("glossy-cornell");
    render::RenderOptions o;
    o.width = w, o.height = h, o.spp = spp, o.seed = 11, o.layers = layers, o.threads = 2;
    return render::Render(scene, o);
}

// The partials split every sample's light exactly; their means are rounded to float one
// by one, so they add up to color within a few float roundings of the parts' magnitude.
// The partial pivots are PivotRadiance's terms: they add up to at most the pivot (the
// rest belongs to the remainder's pivot, not written). The other layers do not change.
TEST(PivotPartials, SumToColorAndLeaveOtherLayersAlone) {
    render::RenderResult r =
        RenderGlossy(20, 16, 4, render::kLayersPivot | render::kLayersPartials);
    render::RenderResult plain = RenderGlossy(20, 16, 4, render::kLayersPivot);
    ASSERT_EQ(r.layers.size(), plain.layers.size() + 7);
    for (const auto &[name, image] : plain.layers)
        EXPECT_TRUE(BitIdentical(image, Layer(r, name))) << name;
    const Image &color = Layer(r, "color"), &pivot = Layer(r, "pivot");
    const Image &c0 = Layer(r, "partial0.color"), &c1 = Layer(r, "partial1.color");
    const Image &p0 = Layer(r, "partial0.pivot"), &p1 = Layer(r, "partial1.pivot");
    const Image &rest = Layer(r, "remainder");
    const Image &v0 = Layer(r, "partial0.variance"), &v1 = Layer(r, "partial1.variance");
    double sum1 = 0, sumRest = 0, sumP1 = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < color.height; ++y)
            for (int x = 0; x < color.width; ++x) {
                double a = c0.At(c, y, x), b = c1.At(c, y, x), e = rest.At(c, y, x);
                double magnitude = std::fabs(a) + std::fabs(b) + std::fabs(e);
                EXPECT_NEAR(a + b + e, color.At(c, y, x), 4 * kUnitRoundoff * magnitude + 1e-30)
                    << x << "," << y << " channel " << c;
                EXPECT_GE(a, 0);
                EXPECT_GE(b, 0);
                EXPECT_GE(e, 0);
                EXPECT_GE(v0.At(c, y, x), 0);
                EXPECT_GE(v1.At(c, y, x), 0);
                double la = pivot.At(c, y, x), q0 = p0.At(c, y, x), q1 = p1.At(c, y, x);
                EXPECT_GT(q0, 0);
                EXPECT_GE(q1, 0);
                EXPECT_LE(q0 + q1, la * (1 + 4 * kUnitRoundoff)) << x << "," << y;
                sum1 += b, sumRest += e, sumP1 += q1;
            }
    // glossy-cornell's walls are 20% mirror: light comes through one and two mirrors.
    EXPECT_GT(sum1, 0);
    EXPECT_GT(sumRest, 0);
    EXPECT_GT(sumP1, 0);
}

class PivotPartialsMethod : public GpuTest {};

PivotInputs PartialInputs(const render::RenderResult &r) {
    PivotInputs in;
    in.color = &Layer(r, "color");
    in.pivot = &Layer(r, "pivot");
    in.variance = &Layer(r, "variance");
    in.normal = &Layer(r, "normal");
    in.objectId = &Layer(r, "objectId");
    in.partId = &Layer(r, "partId");
    for (int k = 0; k < render::kPartialTypes; ++k)
        in.partials.push_back({&Layer(r, fmt::format("partial{}.color", k)),
                               &Layer(r, fmt::format("partial{}.pivot", k)),
                               &Layer(r, fmt::format("partial{}.variance", k))});
    in.remainder = &Layer(r, "remainder");
    return in;
}

// The frame with partials is the single-image pipeline run on each partial against its
// own pivot (and variance), summed in order, plus the remainder: the same float
// operations, so bit for bit; and reruns are bit-identical.
TEST_F(PivotPartialsMethod, FiltersEachPartialAgainstItsOwnPivot) {
    render::RenderResult r = RenderGlossy(
        24, 20, 4, render::kLayersPivot | render::kLayersPartials | render::kLayersGbuffer);
    PivotInputs in = PartialInputs(r);
    for (PivotFilter filter : {PivotFilter::PlaneFit, PivotFilter::Bilateral}) {
        SCOPED_TRACE(fmt::format("filter {}", int(filter)));
        PivotParams o;
        o.filter = filter;
        o.maxRadius = 6;
        o.bilateralRadius = 3;
        PivotResult first = PivotDenoise(Ctx(), in, o);
        PivotResult second = PivotDenoise(Ctx(), in, o);
        EXPECT_TRUE(BitIdentical(first.image, second.image));
        ASSERT_FALSE(first.plan.empty());
        EXPECT_TRUE(Contains(first.plan.front(), "section 8: 2 partial images"));

        Image expected(24, 20, 3);
        for (const PivotPartial &partial : in.partials) {
            PivotInputs one = in;
            one.color = partial.color;
            one.pivot = partial.pivot;
            one.variance = partial.variance;
            one.partials.clear();
            one.remainder = nullptr;
            Image filtered = PivotDenoise(Ctx(), one, o).image;
            for (size_t i = 0; i < expected.Size(); ++i) expected.data[i] += filtered.data[i];
        }
        for (size_t i = 0; i < expected.Size(); ++i) expected.data[i] += in.remainder->data[i];
        EXPECT_TRUE(BitIdentical(expected, first.image));

        // Not the single-image result: the partials change what is filtered.
        PivotInputs whole = in;
        whole.partials.clear();
        whole.remainder = nullptr;
        EXPECT_FALSE(BitIdentical(PivotDenoise(Ctx(), whole, o).image, first.image));
    }
}

// Against the CPU reference pipeline per partial, summed with the remainder: as in
// PivotMethod.MatchesReferenceAndRerunsBitIdentically, a growth decision taken differently
// in float and double moves a few pixels, so nearly all must match to the gather's
// tolerance (64 roundings of the magnitude) and the whole image must be close.
TEST_F(PivotPartialsMethod, MatchesTheReferencePerPartial) {
    render::RenderResult r = RenderGlossy(
        21, 17, 4, render::kLayersPivot | render::kLayersPartials | render::kLayersGbuffer);
    PivotInputs in = PartialInputs(r);
    PivotParams o;
    o.maxRadius = 5;
    PivotResult gpu = PivotDenoise(Ctx(), in, o);

    const PivotParams &p = o;
    Image ids(21, 17, 2);
    for (size_t i = 0; i < ids.PixelCount(); ++i) {
        ids.data[i] = in.objectId->data[i];
        ids.data[ids.PixelCount() + i] = in.partId->data[i];
    }
    ref::PivotGuides guides{in.normal, &ids};
    Image expected = *in.remainder, magnitude = *in.remainder;
    for (const PivotPartial &partial : in.partials) {
        ref::PivotRatio ratio =
            ref::PivotRatioOf(*partial.color, *partial.pivot, partial.variance, p.floor, &ids);
        Image filtered = ref::PivotGather(*partial.color, *partial.pivot, ratio,
                                          ref::PivotFit(ratio, guides, p), guides, p.edge);
        for (size_t i = 0; i < expected.Size(); ++i) {
            expected.data[i] += filtered.data[i];
            magnitude.data[i] +=
                std::fabs(filtered.data[i]) + std::fabs(partial.color->data[i]);
        }
    }
    CompareStats stats;
    (void)ImagesMatch(expected, gpu.image, magnitude, {64 * kUnitRoundoff, 0, 1}, &stats);
    EXPECT_LE(stats.mismatches, expected.Size() / 50) << "nmse " << stats.nmse;
    EXPECT_LT(stats.nmse, 1e-4);
}

TEST_F(PivotPartialsMethod, BadPartialsAreRefusedByName) {
    render::RenderResult r =
        RenderGlossy(8, 6, 2, render::kLayersPivot | render::kLayersPartials);
    PivotInputs in;
    in.color = &Layer(r, "color");
    in.pivot = &Layer(r, "pivot");
    in.partials.push_back({&Layer(r, "partial0.color"), &Layer(r, "partial0.pivot")});
    EXPECT_TRUE(ThrowsError(ErrorKind::MissingLayer, [&] { PivotDenoise(Ctx(), in, {}); }));
    in.remainder = &Layer(r, "remainder");
    Image bad = Layer(r, "partial1.pivot");
    bad.At(2, 3, 5) = NAN;
    in.partials.push_back({&Layer(r, "partial1.color"), &bad});
    // The message names the layer and the pixel.
    std::string message = ErrorOf([&] { PivotDenoise(Ctx(), in, {}); });
    EXPECT_TRUE(Contains(message, "partial1.pivot")) << message;
    EXPECT_TRUE(Contains(message, "(5, 3)")) << message;
    EXPECT_TRUE(ThrowsError(ErrorKind::NonFiniteInput, [&] { PivotDenoise(Ctx(), in, {}); }));
}

}  // namespace
}  // namespace mcd::test
