#include "tools/render/scene.h"

#include <fmt/format.h>

#include <limits>

#include "host/error.h"

namespace mcd::render {

Vec3 Texture::Eval(double u, double v) const {
    switch (kind) {
        case Kind::Constant:
            return a;
        case Kind::Checker: {
            long i = long(std::floor(u * repeat)) + long(std::floor(v * repeat));
            return (i & 1) ? b : a;
        }
        case Kind::Bitmap: {
            if (bitmap.Empty()) return b;
            double fu = u * repeat - std::floor(u * repeat),
                   fv = v * repeat - std::floor(v * repeat);
            int x = std::min(bitmap.width - 1, int(fu * bitmap.width));
            int y = std::min(bitmap.height - 1, int((1 - fv) * bitmap.height));
            double ink = bitmap.At(0, y, x);
            return a * ink + b * (1 - ink);
        }
    }
    return a;
}

Ray Camera::Generate(double x, double y, int width, int height, double lu, double lv) const {
    Vec3 forward = Normalize(target - eye);
    Vec3 right = Normalize(Cross(forward, up));
    Vec3 camUp = Cross(right, forward);
    double halfH = std::tan(fovY * kPi / 360), halfW = halfH * width / height;
    double px = (2 * x / width - 1) * halfW, py = (1 - 2 * y / height) * halfH;
    Vec3 direction = Normalize(forward + right * px + camUp * py);
    if (lensRadius <= 0) return {eye, direction};
    // Thin lens: aim through the point in focus from a uniform point on the lens disk.
    Vec3 focus = eye + direction * (focusDistance / Dot(direction, forward));
    double r = lensRadius * std::sqrt(lu), phi = 2 * kPi * lv;
    Vec3 lens = eye + right * (r * std::cos(phi)) + camUp * (r * std::sin(phi));
    return {lens, Normalize(focus - lens)};
}

namespace {

constexpr double kTMin = 1e-7;

bool IntersectSphere(const Sphere &s, const Ray &ray, double tMax, double *t) {
    Vec3 oc = ray.origin - s.center;
    double b = Dot(oc, ray.direction), c = Dot(oc, oc) - s.radius * s.radius;
    double disc = b * b - c;
    if (disc < 0) return false;
    double root = std::sqrt(disc);
    for (double candidate : {-b - root, -b + root}) {
        if (candidate <= kTMin * (1 + std::fabs(b)) || candidate >= tMax) continue;
        if (ray.At(candidate).y < s.openBelowY) continue;
        *t = candidate;
        return true;
    }
    return false;
}

bool IntersectQuad(const Quad &q, const Ray &ray, double tMax, double *t, double *s,
                   double *r) {
    Vec3 n = Cross(q.edgeU, q.edgeV);
    double denom = Dot(n, ray.direction);
    if (std::fabs(denom) < 1e-14) return false;
    double candidate = Dot(n, q.origin - ray.origin) / denom;
    if (candidate <= kTMin || candidate >= tMax) return false;
    Vec3 w = ray.At(candidate) - q.origin;
    double nn = Dot(n, n);
    double su = Dot(n, Cross(w, q.edgeV)) / nn, sv = Dot(n, Cross(q.edgeU, w)) / nn;
    if (su < 0 || su > 1 || sv < 0 || sv > 1) return false;
    *t = candidate;
    *s = su;
    *r = sv;
    return true;
}

}  // namespace

bool Scene::Intersect(const Ray &ray, double tMax, Hit *hit) const {
    bool found = false;
    for (const Sphere &s : spheres) {
        double t;
        if (!IntersectSphere(s, ray, tMax, &t)) continue;
        tMax = t;
        found = true;
        hit->t = t;
        hit->position = ray.At(t);
        hit->normal = (hit->position - s.center) / s.radius;
        Vec3 d = hit->normal;
        hit->u = 0.5 + std::atan2(d.z, d.x) / (2 * kPi);
        hit->v = 0.5 + std::asin(std::clamp(d.y, -1.0, 1.0)) / kPi;
        hit->material = s.material;
        hit->objectId = s.objectId;
        hit->partId = s.partId;
    }
    for (const Quad &q : quads) {
        double t, u, v;
        if (!IntersectQuad(q, ray, tMax, &t, &u, &v)) continue;
        tMax = t;
        found = true;
        hit->t = t;
        hit->position = ray.At(t);
        hit->normal = q.Normal();
        hit->u = u;
        hit->v = v;
        hit->material = q.material;
        hit->objectId = q.objectId;
        hit->partId = q.partId;
    }
    hit->frontFace = Dot(hit->normal, ray.direction) < 0;
    if (found && !hit->frontFace) hit->normal = -hit->normal;
    return found;
}

bool Scene::Occluded(const Vec3 &from, const Vec3 &to) const {
    Vec3 d = to - from;
    double distance = Length(d);
    Hit hit;
    return Intersect({from, d / distance}, distance * (1 - 1e-7), &hit);
}

Vec3 Scene::Diffuse(const Material &m, const Hit &hit) const {
    return m.diffuseTexture < 0 ? m.diffuse
                                : m.diffuse * textures[m.diffuseTexture].Eval(hit.u, hit.v);
}

Vec3 Scene::Glossy(const Material &m, const Hit &hit) const {
    return m.glossyTexture < 0 ? m.glossy
                               : m.glossy * textures[m.glossyTexture].Eval(hit.u, hit.v);
}

namespace {

int AddMaterial(Scene &scene, Material m) {
    scene.materials.push_back(m);
    return int(scene.materials.size()) - 1;
}

int AddTexture(Scene &scene, Texture t) {
    scene.textures.push_back(std::move(t));
    return int(scene.textures.size()) - 1;
}

void AddQuad(Scene &scene, Vec3 origin, Vec3 u, Vec3 v, int material, int objectId,
             int partId = 0) {
    scene.quads.push_back({origin, u, v, material, objectId, partId});
    if (!scene.materials[material].emission.IsBlack())
        scene.lightQuads.push_back(int(scene.quads.size()) - 1);
}

// An axis-aligned box of the given size standing on y = 0 at `corner`, turned by `degrees`
// about the vertical axis through that corner; five faces (no bottom), one part each.
void AddBox(Scene &scene, Vec3 corner, Vec3 size, double degrees, int material, int objectId) {
    double a = degrees * kPi / 180, c = std::cos(a), s = std::sin(a);
    auto turn = [&](Vec3 p) { return Vec3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z); };
    Vec3 ex = turn({size.x, 0, 0}), ey = {0, size.y, 0}, ez = turn({0, 0, size.z});
    Vec3 o = corner;
    AddQuad(scene, o + ey, ex, ez, material, objectId, 0);  // top
    AddQuad(scene, o, ex, ey, material, objectId, 1);       // front
    AddQuad(scene, o + ez, ex, ey, material, objectId, 2);  // back
    AddQuad(scene, o, ez, ey, material, objectId, 3);       // side
    AddQuad(scene, o + ex, ez, ey, material, objectId, 4);  // other side
}

// Cornell box (the classic dimensions, in metres), checker-textured floor and back wall,
// two boxes, a ceiling area light (Ershov fig. 6, RHF's cornell).
Scene Cornell() {
    Scene scene;
    scene.name = "cornell";
    scene.camera = {{2.78, 2.73, -8.0}, {2.78, 2.73, 0}, {0, 1, 0}, 39.3};
    int checker = AddTexture(scene, {Texture::Kind::Checker, Vec3(1.0), Vec3(0.55), 4});
    int white = AddMaterial(scene, {Vec3(0.73)});
    int floor = AddMaterial(scene, {Vec3(0.73), checker});
    int red = AddMaterial(scene, {Vec3(0.65, 0.05, 0.05)});
    int green = AddMaterial(scene, {Vec3(0.12, 0.45, 0.15)});
    Material lamp{Vec3(0.78)};
    lamp.emission = Vec3(17, 12, 4);
    int light = AddMaterial(scene, lamp);
    const double w = 5.56, h = 5.49, d = 5.59;
    AddQuad(scene, {0, 0, 0}, {w, 0, 0}, {0, 0, d}, floor, 1);  // floor
    AddQuad(scene, {0, h, 0}, {w, 0, 0}, {0, 0, d}, white, 2);  // ceiling
    AddQuad(scene, {0, 0, d}, {w, 0, 0}, {0, h, 0}, floor, 3);  // back wall, textured
    AddQuad(scene, {w, 0, 0}, {0, 0, d}, {0, h, 0}, red,
            4);  // left wall (seen from the camera)
    AddQuad(scene, {0, 0, 0}, {0, 0, d}, {0, h, 0}, green, 5);  // right wall
    AddQuad(scene, {2.13, h - 0.001, 2.27}, {1.30, 0, 0}, {0, 0, 1.05}, light, 6);
    AddBox(scene, {1.30, 0, 0.65}, {1.65, 1.65, 1.65}, -18, white, 7);
    AddBox(scene, {2.65, 0, 2.96}, {1.65, 3.30, 1.65}, 15, white, 8);
    return scene;
}

}  // namespace

std::vector<std::string> SceneNames() {
    return {"cornell"};
}

Scene BuildScene(const std::string &name) {
    if (name == "cornell") return Cornell();
    std::string names;
    for (const std::string &n : SceneNames()) names += (names.empty() ? "" : ", ") + n;
    throw Error(
        fmt::format("unknown scene '{}' (built-in scenes: {}; relief-abc, "
                    "double-textured, glossy-cornell, dof-arealight, interior and "
                    "fireflies are still to come with issue #3)",
                    name, names));
}

}  // namespace mcd::render
