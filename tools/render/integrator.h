// Path tracing with next-event estimation, and the deterministic pivot image.
#pragma once

#include <pcg_random.hpp>

#include <cstdint>

#include "tools/render/scene.h"

namespace mcd::render {

using Rng = pcg32;

// SplitMix64: decorrelates (seed, key) pairs into PCG states.
inline uint64_t Mix(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

inline double Uniform(Rng &rng) {
    return rng() * 0x1p-32;
}

// One camera path. color = direct + indirect exactly, sample by sample: `direct` is light
// reaching the camera through at most one non-specular vertex (emitters seen directly or
// in mirrors, and next-event estimation at the first diffuse or glossy vertex), except
// caustics (a diffuse or glossy vertex, then mirrors, then a light), which count as
// indirect with the rest, diffuse interreflection (Xu-Pattanaik's split). The first hit fills
// the G-buffer fields.
// Ershov section 8: `partial[k]` (k < kPartialTypes) is the light of the paths whose camera
// ray took k mirror bounces before its first diffuse or glossy vertex (or emitter); the
// last entry, the remainder, holds the longer mirror prefixes. They sum to color.
constexpr int kPartialTypes = 2;

struct PathSample {
    Vec3 color, direct, indirect;
    Vec3 partial[kPartialTypes + 1];
    Vec3 albedo, normal;
    double depth = 0;
    int objectId = 0, partId = 0;
};

// Ershov section 5: what one camera sample hands the tracing filter (host/tracing.h) for
// one partial image k (section 8): A_k is the smooth vertex the camera path reaches after
// exactly k mirror bounces. `hasSurface` and the surface fields come from the camera ray's
// deterministic mirror chain (the same for every sample of that ray, whatever lobes it
// picked): A_k's textured lobe weights times the chain's mirror weights, the expectation of
// the prefix throughput, so the pixel's mean of them is the BSDF its partial-k light has.
// `record` when this sample took the k mirror lobes and then a diffuse or glossy lobe at A_k
// (then `pdf` > 0 unless u fell where no smooth lobe samples): `pdf` is u's density among
// all the pixel's samples (the prefix's lobe odds times A_k's mixture density), `radiance`
// the light arriving at A_k along u (no prefix), `own` everything the sample added after u
// was drawn (prefix throughput included).
struct TracingPartial {
    bool hasSurface = false;    // A_k exists: k mirrors, then a diffuse or glossy surface
    Vec3 position, normal, wo;  // of A_k: shading normal, direction towards the camera
    Vec3 diffuse, glossy;       // A_k's textured lobe weights times the mirror chain's
    double kappa = 0;
    bool record = false;  // the sample drew u from A_k's diffuse or glossy lobe
    Vec3 direction;       // u
    double pdf = 0;       // density of u among all the pixel's samples
    Vec3 radiance, own;
};

// color == rest + sum of partial[k].own, sample by sample: `rest` is the light before A_k
// (emission, next-event estimation at A_k), the mirror lobe at the last filtered A_k, and
// the paths of the partials not filtered. `partials` (1..kPartialTypes, set by the caller;
// TracePath keeps it) is how many partial images get records: 1, partial 0 only.
struct TracingPath {
    int partials = 1;
    TracingPartial partial[kPartialTypes];
    Vec3 rest;
};

// `tracing`, when given, is filled for the tracing filter.
PathSample TracePath(const Scene &scene, const Ray &ray, Rng &rng,
                     TracingPath *tracing = nullptr);

// Ershov eq. 9: what the camera would see under unit ambient light with no shadowing:
// texture times the directional albedo of the surface's BSDF (Lambert: its albedo;
// glossy: its weight when the mirror direction is above the surface), mirror chains
// followed deterministically up to a depth limit, 1 for rays that escape.
Vec3 PivotRadiance(const Scene &scene, const Ray &ray, int depth = 0);

// PivotRadiance split by the number k of mirror bounces before the term: partial[k] is the
// pivot of the section-8 partial image k (the same camera ray path before its first
// diffuse or glossy hit); the remainder entry holds k >= kPartialTypes. They sum to
// PivotRadiance to round-off.
void PivotPartials(const Scene &scene, const Ray &ray, Vec3 partial[kPartialTypes + 1]);

}  // namespace mcd::render
