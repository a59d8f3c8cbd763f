#include "tools/render/scene.h"

#include <fmt/format.h>

#include <limits>

#include "host/error.h"
#include "tools/render/text.h"

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

// Shading normal of a quad's relief h(s, t) = relief * sum_i sin(k_i . (s, t) + phase_i), in
// metres along the edges: n - dh/ds u - dh/dt v.
Vec3 ReliefNormal(const Quad &q, double u, double v) {
    double lu = Length(q.edgeU), lv = Length(q.edgeV);
    double s = u * lu, t = v * lv, k = 2 * kPi / q.reliefWavelength;
    // Fixed directions and phases: the same relief in every run.
    const double dirs[4][2] = {{1, 0.3}, {-0.4, 1}, {0.7, 0.7}, {0.9, -0.5}};
    const double phases[4] = {0.3, 1.7, 4.1, 2.2}, scales[4] = {1, 1.3, 0.7, 1.9};
    double ds = 0, dt = 0;
    for (int i = 0; i < 4; ++i) {
        double kx = k * scales[i] * dirs[i][0], ky = k * scales[i] * dirs[i][1];
        double c = q.relief * std::cos(kx * s + ky * t + phases[i]) / 4;
        ds += c * kx;
        dt += c * ky;
    }
    return Normalize(q.Normal() - q.edgeU / lu * ds - q.edgeV / lv * dt);
}

}  // namespace

bool Scene::Intersect(const Ray &ray, double tMax, Hit *hit) const {
    bool found = false;
    Vec3 geometric;
    for (const Sphere &s : spheres) {
        double t;
        if (!IntersectSphere(s, ray, tMax, &t)) continue;
        tMax = t;
        found = true;
        hit->t = t;
        hit->position = ray.At(t);
        hit->normal = (hit->position - s.center) / s.radius;
        geometric = hit->normal;
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
        geometric = hit->normal;
        if (q.relief > 0) hit->normal = ReliefNormal(q, u, v);
        hit->u = u;
        hit->v = v;
        hit->material = q.material;
        hit->objectId = q.objectId;
        hit->partId = q.partId;
    }
    // Sidedness from the geometric normal; the shading normal follows it.
    hit->frontFace = Dot(geometric, ray.direction) < 0;
    hit->geometricNormal = hit->frontFace ? geometric : -geometric;
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

// Lettering seen from the camera side (-z): +x is on the image's left with the camera
// convention of the classic Cornell data, so the bitmap is mirrored to read left to right.
int TextTexture(Scene &scene, const std::string &word, Vec3 ink, Vec3 paper, double repeat) {
    Texture t{Texture::Kind::Bitmap, ink, paper, repeat};
    Image text = TextBitmap(word, 96);
    t.bitmap = text;
    for (int y = 0; y < text.height; ++y)
        for (int x = 0; x < text.width; ++x)
            t.bitmap.At(0, y, x) = text.At(0, y, text.width - 1 - x);
    return AddTexture(scene, std::move(t));
}

// Cornell box with 20% mirror and 60% glossy surfaces and two boxes lettered "ABC"
// (Ershov 7.3).
Scene GlossyCornell() {
    Scene scene = Cornell();
    scene.name = "glossy-cornell";
    int abc = TextTexture(scene, "ABC", Vec3(0.1, 0.1, 0.5), Vec3(0.9), 1);
    for (Material &m : scene.materials) {
        if (!m.emission.IsBlack()) continue;
        m.glossy = m.diffuse * 0.6;
        m.glossyKappa = 150;
        m.mirror = Vec3(0.2);
        m.diffuse = m.diffuse * 0.2;
    }
    Material lettered{Vec3(0.2), abc};
    lettered.glossy = Vec3(0.6);
    lettered.glossyTexture = abc;
    lettered.glossyKappa = 150;
    int boxes = AddMaterial(scene, lettered);
    for (Quad &q : scene.quads)
        if (q.objectId >= 7) q.material = boxes;
    return scene;
}

// A point light inside a matte spherical shade, open below, `height` above the floor.
void AddShadedLamp(Scene &scene, double height, int objectId) {
    int shade = AddMaterial(scene, {Vec3(0.7)});
    scene.spheres.push_back({{0, height, 0}, 0.15, shade, objectId, 0, height - 0.08});
    scene.pointLights.push_back({{0, height, 0}, Vec3(8)});
}

// 2x2 m plane with a random relief and a glossy lobe lettered "ABC", lit by a point light
// in a matte shade 1.5 m above (Ershov 7.1).
Scene ReliefAbc() {
    Scene scene;
    scene.name = "relief-abc";
    scene.camera = {{0, 1.6, -2.2}, {0, 0, 0.1}, {0, 1, 0}, 45};
    int abc = TextTexture(scene, "ABC", Vec3(1.0), Vec3(0.25), 1);
    Material plane{Vec3(0.3), abc};
    plane.glossy = Vec3(0.6);
    plane.glossyTexture = abc;
    plane.glossyKappa = 60;
    int m = AddMaterial(scene, plane);
    AddQuad(scene, {-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, m, 1);
    scene.quads.back().relief = 0.004;
    scene.quads.back().reliefWavelength = 0.08;
    AddShadedLamp(scene, 1.5, 2);
    return scene;
}

// 5x5 m plane: Lambert 0.5 times a chessboard plus a glossy lobe 0.5 times repeated
// "FRONT", the same lamp (Ershov 7.2).
Scene DoubleTextured() {
    Scene scene;
    scene.name = "double-textured";
    scene.camera = {{0, 1.8, -3.2}, {0, 0, 0.6}, {0, 1, 0}, 50};
    int chess = AddTexture(scene, {Texture::Kind::Checker, Vec3(1.0), Vec3(0.15), 10});
    int front = TextTexture(scene, "FRONT", Vec3(1.0), Vec3(0.1), 4);
    Material plane{Vec3(0.5), chess};
    plane.glossy = Vec3(0.5);
    plane.glossyTexture = front;
    plane.glossyKappa = 80;
    int m = AddMaterial(scene, plane);
    AddQuad(scene, {-2.5, 0, -2.5}, {5, 0, 0}, {0, 0, 5}, m, 1);
    AddShadedLamp(scene, 1.5, 2);
    return scene;
}

// Objects spread in depth, thin-lens depth of field, a rectangular area light with soft
// shadows, a textured floor (AWR's toasters and chess: a 6D integrand).
Scene DofArealight() {
    Scene scene;
    scene.name = "dof-arealight";
    scene.camera = {{0, 1.0, -4.0}, {0, 0.5, 2.0}, {0, 1, 0}, 40, 0.08, 6.0};
    int checker = AddTexture(scene, {Texture::Kind::Checker, Vec3(0.8), Vec3(0.2), 8});
    int floor = AddMaterial(scene, {Vec3(1.0), checker});
    AddQuad(scene, {-4, 0, -2}, {8, 0, 0}, {0, 0, 10}, floor, 1);
    const Vec3 colors[5] = {
        {0.8, 0.2, 0.2}, {0.2, 0.7, 0.2}, {0.2, 0.3, 0.8}, {0.8, 0.7, 0.2}, {0.7, 0.7, 0.7}};
    for (int i = 0; i < 5; ++i) {
        Material m{colors[i]};
        if (i % 2) m.glossy = Vec3(0.3), m.glossyKappa = 100;
        int material = AddMaterial(scene, m);
        scene.spheres.push_back(
            {{-1.6 + 0.8 * i, 0.45, -0.5 + 1.6 * i}, 0.45, material, 2 + i});
    }
    Material lamp{Vec3(0.5)};
    lamp.emission = Vec3(12);
    int light = AddMaterial(scene, lamp);
    // Edge order sets the emitting side: this one faces down onto the scene.
    AddQuad(scene, {-2.5, 3.0, 0.5}, {1.0, -0.2, 0}, {0, 0, 1.5}, light, 9);
    return scene;
}

// A room lit mostly indirectly: a bright sky patch shines through a window in the left
// wall onto the floor, the rest of the room sees it through interreflection
// (Xu-Pattanaik's cabin and conference room).
Scene Interior() {
    Scene scene;
    scene.name = "interior";
    const double w = 4, h = 2.8, d = 5;
    scene.camera = {{0.4, 1.4, 0.3}, {-0.6, 1.0, 4.0}, {0, 1, 0}, 60};
    int wood = AddTexture(
        scene, {Texture::Kind::Checker, Vec3(0.75, 0.55, 0.35), Vec3(0.6, 0.42, 0.25), 6});
    int floor = AddMaterial(scene, {Vec3(1.0), wood});
    int wall = AddMaterial(scene, {Vec3(0.75, 0.73, 0.7)});
    int blue = AddMaterial(scene, {Vec3(0.2, 0.3, 0.6)});
    Material sunlight{Vec3(0)};
    sunlight.emission = Vec3(640, 590, 520);
    int sun = AddMaterial(scene, sunlight);
    double x0 = -w / 2, x1 = w / 2;
    AddQuad(scene, {x0, 0, 0}, {w, 0, 0}, {0, 0, d}, floor, 1);
    AddQuad(scene, {x0, h, 0}, {w, 0, 0}, {0, 0, d}, wall, 2);
    AddQuad(scene, {x0, 0, d}, {w, 0, 0}, {0, h, 0}, wall, 3);
    AddQuad(scene, {x0, 0, 0}, {w, 0, 0}, {0, h, 0}, wall, 4);
    AddQuad(scene, {x1, 0, 0}, {0, 0, d}, {0, h, 0}, wall, 5);
    // Left wall with a window 1.2 m wide, from 0.9 m to 2.1 m high, centred in depth.
    double wz0 = 1.9, wz1 = 3.1, wy0 = 0.9, wy1 = 2.1;
    AddQuad(scene, {x0, 0, 0}, {0, 0, wz0}, {0, h, 0}, wall, 6, 0);
    AddQuad(scene, {x0, 0, wz1}, {0, 0, d - wz1}, {0, h, 0}, wall, 6, 1);
    AddQuad(scene, {x0, 0, wz0}, {0, 0, wz1 - wz0}, {0, wy0, 0}, wall, 6, 2);
    AddQuad(scene, {x0, wy1, wz0}, {0, 0, wz1 - wz0}, {0, h - wy1, 0}, wall, 6, 3);
    // The sun: a small, bright quad outside, aimed through the window at the floor in view.
    Vec3 target(-0.8, 0, 3.0), window(x0, 1.5, 2.5);
    Vec3 toSun = window - target, facing = Normalize(-toSun);
    Vec3 e1 = Normalize(Cross(Vec3(0, 1, 0), facing)) * 0.6, e2 = Cross(facing, e1 / 0.6) * 0.6;
    Vec3 centre = window + toSun * 2.0;
    AddQuad(scene, centre - e1 * 0.5 - e2 * 0.5, e1, e2, sun, 7);
    AddBox(scene, {0.4, 0, 3.2}, {0.9, 0.75, 0.6}, 20, blue, 8);
    return scene;
}

// Rare bright paths: a small, very bright light above a mirror sphere casts a caustic
// that only BSDF sampling finds (light -> mirror -> floor), impulse noise for RHF's kNN;
// a dim large light keeps the rest visible.
Scene Fireflies() {
    Scene scene;
    scene.name = "fireflies";
    scene.camera = {{0, 1.2, -3.0}, {0, 0.4, 0.5}, {0, 1, 0}, 45};
    int floor = AddMaterial(scene, {Vec3(0.7)});
    int wall = AddMaterial(scene, {Vec3(0.6, 0.6, 0.65)});
    Material chrome{Vec3(0)};
    chrome.mirror = Vec3(0.95);
    int mirror = AddMaterial(scene, chrome);
    Material hot{Vec3(0)};
    hot.emission = Vec3(4000);
    int small = AddMaterial(scene, hot);
    Material soft{Vec3(0)};
    soft.emission = Vec3(1.5);
    int big = AddMaterial(scene, soft);
    AddQuad(scene, {-3, 0, -3}, {6, 0, 0}, {0, 0, 6}, floor, 1);
    AddQuad(scene, {-3, 0, 2}, {6, 0, 0}, {0, 3, 0}, wall, 2);
    scene.spheres.push_back({{0.3, 0.5, 0.6}, 0.5, mirror, 3});
    AddQuad(scene, {0.25, 2.0, 0.5}, {0.04, 0, 0}, {0, 0, 0.04}, small, 4);
    AddQuad(scene, {-3, 2.9, -3}, {6, 0, 0}, {0, 0, 5}, big, 5);
    return scene;
}

}  // namespace

std::vector<std::string> SceneNames() {
    return {"cornell",       "relief-abc", "double-textured", "glossy-cornell",
            "dof-arealight", "interior",   "fireflies"};
}

Scene BuildScene(const std::string &name) {
    if (name == "cornell") return Cornell();
    if (name == "relief-abc") return ReliefAbc();
    if (name == "double-textured") return DoubleTextured();
    if (name == "glossy-cornell") return GlossyCornell();
    if (name == "dof-arealight") return DofArealight();
    if (name == "interior") return Interior();
    if (name == "fireflies") return Fireflies();
    std::string names;
    for (const std::string &n : SceneNames()) names += (names.empty() ? "" : ", ") + n;
    throw Error(fmt::format("unknown scene '{}' (built-in scenes: {})", name, names),
                ErrorKind::InvalidArgument);
}

}  // namespace mcd::render
