#include "tools/render/integrator.h"

#include <algorithm>
#include <limits>

namespace mcd::render {
namespace {

// A safety cap only: Russian roulette ends paths long before (a low cap lost light in a
// closed box of bright albedo).
constexpr int kMaxDepth = 256;
constexpr int kPivotDepth = 8;

// Density of the von Mises-Fisher lobe of concentration kappa around unit `axis`.
double VmfPdf(const Vec3 &w, const Vec3 &axis, double kappa) {
    return kappa / (2 * kPi * -std::expm1(-2 * kappa)) * std::exp(kappa * (Dot(w, axis) - 1));
}

Vec3 SampleVmf(const Vec3 &axis, double kappa, double u1, double u2) {
    double w = 1 + std::log(u1 + (1 - u1) * std::exp(-2 * kappa)) / kappa;
    w = std::clamp(w, -1.0, 1.0);
    double r = std::sqrt(std::max(0.0, 1 - w * w)), phi = 2 * kPi * u2;
    return Frame(axis).ToWorld({r * std::cos(phi), r * std::sin(phi), w});
}

Vec3 SampleCosine(const Vec3 &n, double u1, double u2) {
    double r = std::sqrt(u1), phi = 2 * kPi * u2;
    return Frame(n).ToWorld({r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - u1)});
}

// Leave the surface on the side the ray is going, along the geometric normal (a relief's
// shading normal may lean across the surface).
Vec3 Offset(const Hit &hit, const Vec3 &direction) {
    double side = Dot(direction, hit.geometricNormal) >= 0 ? 1 : -1;
    return hit.position + hit.geometricNormal * (side * 1e-7 * (1 + Length(hit.position)));
}

// f(wo, wi) cos(theta_i) of the diffuse and glossy parts (the mirror is a delta).
Vec3 SmoothBsdfCos(const Scene &scene, const Material &m, const Hit &hit, const Vec3 &wo,
                   const Vec3 &wi) {
    double cosI = Dot(wi, hit.normal);
    if (cosI <= 0) return Vec3(0);
    Vec3 f = scene.Diffuse(m, hit) * (cosI / kPi);
    if (!m.glossy.IsBlack())
        f += scene.Glossy(m, hit) * VmfPdf(wi, Reflect(-wo, hit.normal), m.glossyKappa);
    return f;
}

// Light reaching `hit` from the lights, one sample of the area lights (chosen by area)
// plus every point light, through the smooth part of the BSDF.
Vec3 DirectLight(const Scene &scene, const Material &m, const Hit &hit, const Vec3 &wo,
                 Rng &rng) {
    Vec3 sum(0);
    Vec3 origin = Offset(hit, hit.geometricNormal);
    for (const PointLight &light : scene.pointLights) {
        Vec3 d = light.position - origin;
        double dist2 = Dot(d, d);
        Vec3 wi = d / std::sqrt(dist2);
        Vec3 f = SmoothBsdfCos(scene, m, hit, wo, wi);
        if (f.IsBlack() || scene.Occluded(origin, light.position)) continue;
        sum += f * light.intensity / dist2;
    }
    if (!scene.lightQuads.empty()) {
        // Pick a light in proportion to its power (area x brightest emission channel): a
        // tiny bright light then gets the samples its light deserves.
        auto power = [&](int q) {
            return scene.quads[q].Area() *
                   scene.materials[scene.quads[q].material].emission.MaxComponent();
        };
        double total = 0;
        for (int q : scene.lightQuads) total += power(q);
        double pick = Uniform(rng) * total;
        int chosen = scene.lightQuads.back();
        for (int q : scene.lightQuads) {
            pick -= power(q);
            if (pick < 0) {
                chosen = q;
                break;
            }
        }
        const Quad *quad = &scene.quads[chosen];
        double u = Uniform(rng), v = Uniform(rng);  // in this order on every compiler
        Vec3 p = quad->origin + quad->edgeU * u + quad->edgeV * v;
        Vec3 d = p - origin;
        double dist2 = Dot(d, d), dist = std::sqrt(dist2);
        Vec3 wi = d / dist;
        double cosL = -Dot(quad->Normal(), wi);  // emits on its normal's side only
        if (cosL > 0) {
            Vec3 f = SmoothBsdfCos(scene, m, hit, wo, wi);
            // pdf of the point: (power / total) / area.
            double inversePdf = total * quad->Area() / power(chosen);
            if (!f.IsBlack() && !scene.Occluded(origin, p))
                sum +=
                    f * scene.materials[quad->material].emission * (cosL * inversePdf / dist2);
        }
    }
    return sum;
}

// Section 8's A_k for k = 1..partials-1: follow the camera ray's mirror chain from its
// first hit (the mirror direction at each vertex, as a path that picks the mirror lobes
// takes it) and give partial k the surface of its k-th vertex where that is smooth, its
// lobe weights times the chain's mirror weights (the expectation of a sample's prefix
// throughput: lobe odds wm / total times factor mirror * total / wm).
void MirrorChainSurfaces(const Scene &scene, const Ray &cameraRay, const Hit &firstHit,
                         TracingPath *tracing) {
    Ray ray = cameraRay;
    Vec3 weight(1);
    Hit hit = firstHit;
    for (int k = 0; k < tracing->partials; ++k) {
        if (k > 0 && !scene.Intersect(ray, std::numeric_limits<double>::infinity(), &hit))
            return;
        const Material &m = scene.materials[hit.material];
        Vec3 diffuse = scene.Diffuse(m, hit), glossy = scene.Glossy(m, hit);
        if (k > 0 && diffuse.MaxComponent() + glossy.MaxComponent() > 0) {
            TracingPartial &a = tracing->partial[k];
            a.hasSurface = true;
            a.position = hit.position;
            a.normal = hit.normal;
            a.wo = -ray.direction;
            a.diffuse = weight * diffuse;
            a.glossy = weight * glossy;
            a.kappa = m.glossyKappa;
        }
        if (m.mirror.MaxComponent() <= 0) return;
        Vec3 wi = Reflect(ray.direction, hit.normal);
        if (Dot(wi, hit.geometricNormal) <= 0) return;  // the path is absorbed there too
        weight *= m.mirror;
        ray = {Offset(hit, wi), wi};
    }
}

// One camera path as it bounces (TracePath): what it has gathered and where it stands.
class PathTracer {
  public:
    PathTracer(const Scene &scene, Rng &rng, TracingPath *tracing)
        : scene(scene), rng(rng), tracing(tracing) {
        if (!tracing) return;
        partials = std::clamp(tracing->partials, 1, kPartialTypes);
        *tracing = TracingPath();
        tracing->partials = partials;
    }

    PathSample Trace(const Ray &cameraRay) {
        ray = cameraRay;
        for (int depth = 0; depth < kMaxDepth; ++depth)
            if (!Bounce(depth)) break;
        out.color = out.direct + out.indirect;
        return out;
    }

  private:
    // A vertex's textured lobe weights and the odds of picking each.
    struct Lobes {
        Vec3 diffuse, glossy;
        double wd = 0, wg = 0, wm = 0, total = 0;
    };
    // The lobe a path continues through: the direction, its throughput factor.
    struct Choice {
        Vec3 wi, factor;
        bool smooth = false;  // diffuse or glossy
        bool glossy = false;
    };

    bool Bounce(int depth);
    void AddLight(const Vec3 &light);
    void AddFromA(const Vec3 &light);
    void RecordFirstHit(const Hit &hit, const Material &m);
    TracingPartial *StartPartial(int depth, const Hit &hit, const Material &m, const Lobes &l,
                                 const Vec3 &wo);
    Choice PickLobe(const Hit &hit, const Material &m, const Lobes &l);
    void RecordDirection(TracingPartial &atA, const Choice &c, const Hit &hit,
                         const Material &m, const Lobes &l) const;
    bool Continue(int depth, const Hit &hit, const Choice &c, TracingPartial *atA,
                  const Lobes &l);

    const Scene &scene;
    Rng &rng;
    TracingPath *tracing;
    PathSample out;
    int partials = 0;
    // After u was drawn at A_k: light is partial k's filtered part, and `fromA` carries it
    // back to A_k (the throughput since A_k, Russian roulette included).
    TracingPartial *afterA = nullptr;
    Vec3 fromA = Vec3(1);
    double prefixOdds = 1;  // probability of the mirror lobes picked before A_k
    Ray ray;
    Vec3 throughput = Vec3(1);
    int smoothVertices = 0;     // diffuse or glossy vertices so far
    bool afterSpecular = true;  // the last vertex was the camera or a mirror
    int mirrorPrefix = 0;       // mirror bounces before the first smooth vertex
};

// Add to direct or indirect, and to the partial image of the path's mirror prefix.
void PathTracer::AddLight(const Vec3 &light) {
    (smoothVertices == 0 ? out.direct : out.indirect) += light;
    out.partial[std::min(mirrorPrefix, kPartialTypes)] += light;
    if (!tracing) return;
    if (afterA)
        afterA->own += light;
    else
        tracing->rest += light;
}

// The same light carried back to A only: the radiance arriving there along u.
void PathTracer::AddFromA(const Vec3 &light) {
    if (afterA) afterA->radiance += fromA * light;
}

// The G-buffer fields from the first hit.
void PathTracer::RecordFirstHit(const Hit &hit, const Material &m) {
    out.albedo = scene.Diffuse(m, hit) + scene.Glossy(m, hit) + m.mirror;
    out.normal = hit.normal;
    out.depth = hit.t;
    out.objectId = hit.objectId;
    out.partId = hit.partId;
}

// A_k: the first diffuse or glossy vertex, after k < partials mirror bounces; its surface
// (and, at the first hit, the mirror chain's) for the tracing filter.
TracingPartial *PathTracer::StartPartial(int depth, const Hit &hit, const Material &m,
                                         const Lobes &l, const Vec3 &wo) {
    TracingPartial *atA = tracing && smoothVertices == 0 && depth < partials && l.wd + l.wg > 0
                              ? &tracing->partial[depth]
                              : nullptr;
    if (tracing && depth == 0 && partials > 1 && !m.mirror.IsBlack())
        MirrorChainSurfaces(scene, ray, hit, tracing);
    if (atA && depth == 0) {
        atA->hasSurface = true;
        atA->position = hit.position;
        atA->normal = hit.normal;
        atA->wo = wo;
        atA->diffuse = l.diffuse;
        atA->glossy = l.glossy;
        atA->kappa = m.glossyKappa;
    }
    return atA;
}

// Pick one lobe in proportion to its weight and the direction the path continues in.
PathTracer::Choice PathTracer::PickLobe(const Hit &hit, const Material &m, const Lobes &l) {
    double pick = Uniform(rng) * l.total, u1 = Uniform(rng), u2 = Uniform(rng);
    Choice c;
    c.smooth = pick < l.wd + l.wg;
    c.glossy = pick >= l.wd && c.smooth;
    if (pick < l.wd) {
        c.wi = SampleCosine(hit.normal, u1, u2);
        c.factor = l.diffuse * (l.total / l.wd);
    } else if (c.smooth) {
        c.wi = SampleVmf(Reflect(ray.direction, hit.normal), m.glossyKappa, u1, u2);
        c.factor = l.glossy * (l.total / l.wg);
    } else {
        c.wi = Reflect(ray.direction, hit.normal);
        c.factor = m.mirror * (l.total / l.wm);
    }
    return c;
}

// The density of u among all of A's samples: each lobe's, times its odds, times the odds
// of the mirror prefix.
void PathTracer::RecordDirection(TracingPartial &atA, const Choice &c, const Hit &hit,
                                 const Material &m, const Lobes &l) const {
    atA.record = true;
    atA.direction = c.wi;
    double cosI = Dot(c.wi, hit.normal);
    double pdf = (l.wd / l.total) * std::max(cosI, 0.0) / kPi;
    if (l.wg > 0)
        pdf +=
            (l.wg / l.total) * VmfPdf(c.wi, Reflect(ray.direction, hit.normal), m.glossyKappa);
    atA.pdf = prefixOdds * pdf;
}

// Carry the path through the chosen lobe; false when it ends here.
bool PathTracer::Continue(int depth, const Hit &hit, const Choice &c, TracingPartial *atA,
                          const Lobes &l) {
    // The glossy lobe's mass below the surface is lost.
    if (c.glossy && Dot(c.wi, hit.normal) <= 0) return false;
    throughput *= c.factor;
    if (afterA) fromA *= c.factor;
    if (atA && c.smooth) afterA = atA;
    if (c.smooth) {
        ++smoothVertices;
        afterSpecular = false;
    } else {
        afterSpecular = true;
        if (smoothVertices == 0) ++mirrorPrefix, prefixOdds *= l.wm / l.total;
    }
    // A bent shading normal can send a direction under the surface: absorb it.
    if (Dot(c.wi, hit.geometricNormal) <= 0) return false;
    // Russian roulette once the path has some length.
    if (depth >= 3) {
        double survive = std::min(0.95, throughput.MaxComponent());
        if (Uniform(rng) >= survive) return false;
        throughput = throughput / survive;
        fromA = fromA / survive;
    }
    ray = {Offset(hit, c.wi), c.wi};
    return true;
}

// One vertex: its emission, next-event estimation, the tracing filter's records and the
// next direction; false when the path ends here.
bool PathTracer::Bounce(int depth) {
    Hit hit;
    if (!scene.Intersect(ray, std::numeric_limits<double>::infinity(), &hit)) return false;
    const Material &m = scene.materials[hit.material];
    Vec3 wo = -ray.direction;
    if (depth == 0) RecordFirstHit(hit, m);
    // Emission counts when no light sample could have found it: right after the camera
    // or a mirror (mirror chains after a smooth vertex carry caustics: indirect).
    if (!m.emission.IsBlack() && hit.frontFace && afterSpecular) {
        AddLight(throughput * m.emission);
        AddFromA(m.emission);
    }
    Lobes l;
    l.diffuse = scene.Diffuse(m, hit);
    l.glossy = scene.Glossy(m, hit);
    l.wd = l.diffuse.MaxComponent();
    l.wg = l.glossy.MaxComponent();
    l.wm = m.mirror.MaxComponent();
    l.total = l.wd + l.wg + l.wm;
    if (l.total <= 0) return false;
    if (l.wd + l.wg > 0) {
        Vec3 direct = DirectLight(scene, m, hit, wo, rng);
        AddLight(throughput * direct);
        AddFromA(direct);
    }
    TracingPartial *atA = StartPartial(depth, hit, m, l, wo);
    Choice c = PickLobe(hit, m, l);
    if (atA && c.smooth) RecordDirection(*atA, c, hit, m, l);
    return Continue(depth, hit, c, atA, l);
}

}  // namespace

PathSample TracePath(const Scene &scene, const Ray &cameraRay, Rng &rng, TracingPath *tracing) {
    return PathTracer(scene, rng, tracing).Trace(cameraRay);
}

Vec3 PivotRadiance(const Scene &scene, const Ray &ray, int depth) {
    Hit hit;
    if (!scene.Intersect(ray, std::numeric_limits<double>::infinity(), &hit)) return Vec3(1);
    const Material &m = scene.materials[hit.material];
    Vec3 radiance = scene.Diffuse(m, hit);
    Vec3 mirrorDir = Reflect(ray.direction, hit.normal);
    if (Dot(mirrorDir, hit.normal) > 0) radiance += scene.Glossy(m, hit);
    if (!m.mirror.IsBlack() && depth < kPivotDepth)
        radiance +=
            m.mirror * PivotRadiance(scene, {Offset(hit, mirrorDir), mirrorDir}, depth + 1);
    return radiance;
}

void PivotPartials(const Scene &scene, const Ray &cameraRay, Vec3 partial[kPartialTypes + 1]) {
    for (int k = 0; k <= kPartialTypes; ++k) partial[k] = Vec3(0);
    // PivotRadiance unrolled: the term found after k mirrors, times their product.
    Ray ray = cameraRay;
    Vec3 weight(1);
    for (int depth = 0; depth <= kPivotDepth; ++depth) {
        Vec3 &term = partial[std::min(depth, kPartialTypes)];
        Hit hit;
        if (!scene.Intersect(ray, std::numeric_limits<double>::infinity(), &hit)) {
            term += weight;
            return;
        }
        const Material &m = scene.materials[hit.material];
        Vec3 own = scene.Diffuse(m, hit);
        Vec3 mirrorDir = Reflect(ray.direction, hit.normal);
        if (Dot(mirrorDir, hit.normal) > 0) own += scene.Glossy(m, hit);
        term += weight * own;
        if (m.mirror.IsBlack() || depth == kPivotDepth) return;
        weight *= m.mirror;
        ray = {Offset(hit, mirrorDir), mirrorDir};
    }
}

}  // namespace mcd::render
