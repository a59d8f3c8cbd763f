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

// Ershov section 5: what one camera sample hands the tracing filter (host/tracing.h). Set
// for partial-0 paths (the first hit A is diffuse or glossy, no mirror before it); `record`
// when the lobe picked at A was diffuse or glossy (then `pdf` > 0 unless u fell where no
// smooth lobe samples). color == rest + own, sample by sample: `own` is everything added
// after the direction u was drawn at A (`radiance` times A's lobe weight), `rest` the rest
// (light before A, next-event estimation at A, the mirror lobe at A, other paths).
struct TracingPath {
    bool hasSurface = false;    // A exists: the first hit is diffuse or glossy
    Vec3 position, normal, wo;  // of A: shading normal, direction towards the camera
    Vec3 diffuse, glossy;       // A's textured lobe weights
    double kappa = 0;
    bool record = false;  // u was drawn from A's diffuse or glossy lobe
    Vec3 direction;       // u
    double pdf = 0;       // mixture density of u among all of A's lobes
    Vec3 radiance, own, rest;
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
