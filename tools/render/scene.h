// The built-in scenes: analytic shapes (spheres, parallelograms), textured materials,
// area and point lights, a thin-lens camera. Small enough that a linear intersection
// loop is the acceleration structure.
#pragma once

#include <string>
#include <vector>

#include "host/image.h"
#include "tools/render/geometry.h"

namespace mcd::render {

// A reflectance texture over a surface's (u, v) in [0,1]^2.
struct Texture {
    enum class Kind { Constant, Checker, Bitmap } kind = Kind::Constant;
    Vec3 a{1}, b{1};    // constant: a; checker: a/b squares; bitmap: a where ink, b elsewhere
    double repeat = 1;  // checker squares (or bitmap tiles) per unit of u and v
    Image bitmap;       // 1 channel coverage in [0,1]
    Vec3 Eval(double u, double v) const;
};

// Lambert + glossy (a von Mises-Fisher lobe around the mirror direction, energy
// conserving: f cos integrates to `glossy` over the sphere) + ideal mirror, each
// optionally modulated by a texture, plus emission.
struct Material {
    Vec3 diffuse{0};
    int diffuseTexture = -1;
    Vec3 glossy{0};
    int glossyTexture = -1;
    double glossyKappa = 200;  // lobe concentration: larger is sharper
    Vec3 mirror{0};
    Vec3 emission{0};
};

struct Sphere {
    Vec3 center;
    double radius = 1;
    int material = 0, objectId = 0, partId = 0;
    // Open below this height (a lamp shade's opening); -inf: closed.
    double openBelowY = -1e300;
};

// The parallelogram origin + s * edgeU + t * edgeV, s, t in [0, 1]; (s, t) is its (u, v).
struct Quad {
    Vec3 origin, edgeU, edgeV;
    int material = 0, objectId = 0, partId = 0;
    // Relief: a fixed sum of sines of this amplitude (metres) and wavelength bends the
    // shading normal; 0: flat.
    double relief = 0, reliefWavelength = 0.1;
    Vec3 Normal() const { return Normalize(Cross(edgeU, edgeV)); }
    double Area() const { return Length(Cross(edgeU, edgeV)); }
};

struct PointLight {
    Vec3 position, intensity;
};

struct Camera {
    Vec3 eye, target, up{0, 1, 0};
    double fovY = 40;       // degrees
    double lensRadius = 0;  // 0: pinhole
    double focusDistance = 1;
    // Ray through image position (x, y) in pixels (y down), lens sample (lu, lv) in [0,1)^2.
    Ray Generate(double x, double y, int width, int height, double lu, double lv) const;
};

struct Hit {
    double t = 0;
    Vec3 position, normal;  // shading normal, facing the incoming ray
    Vec3 geometricNormal;   // the surface's own normal, facing the incoming ray
    bool frontFace = true;  // the ray came from the side the surface's normal points to
    double u = 0, v = 0;
    int material = -1, objectId = 0, partId = 0;
};

struct Scene {
    std::string name;
    Camera camera;
    std::vector<Texture> textures;
    std::vector<Material> materials;
    std::vector<Sphere> spheres;
    std::vector<Quad> quads;
    std::vector<int> lightQuads;  // indices of emissive quads
    std::vector<PointLight> pointLights;

    bool Intersect(const Ray &ray, double tMax, Hit *hit) const;
    bool Occluded(const Vec3 &from, const Vec3 &to) const;
    Vec3 Diffuse(const Material &m, const Hit &hit) const;
    Vec3 Glossy(const Material &m, const Hit &hit) const;
};

// Names of the built-in scenes, and one by name (throws mcd::Error listing the names).
std::vector<std::string> SceneNames();
Scene BuildScene(const std::string &name);

}  // namespace mcd::render
