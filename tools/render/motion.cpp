#include "tools/render/motion.h"

#include <cmath>
#include <limits>

namespace mcd::render {

Camera CameraAt(const Camera &camera, const Vec3 &step, double frame) {
    Camera moved = camera;
    moved.eye = camera.eye + step * frame;
    moved.target = camera.target + step * frame;
    return moved;
}

// The inverse of Camera::Generate for a pinhole: the camera frame's axes, the point's
// coordinates along them, and the image plane at distance 1.
bool Project(const Camera &camera, const Vec3 &p, int width, int height, double *x, double *y) {
    Vec3 forward = Normalize(camera.target - camera.eye);
    Vec3 right = Normalize(Cross(forward, camera.up));
    Vec3 camUp = Cross(right, forward);
    Vec3 d = p - camera.eye;
    double depth = Dot(d, forward);
    if (!(depth > 0)) return false;
    double halfH = std::tan(camera.fovY * kPi / 360), halfW = halfH * width / height;
    double px = Dot(d, right) / depth, py = Dot(d, camUp) / depth;
    *x = (px / halfW + 1) * width / 2;
    *y = (1 - py / halfH) * height / 2;
    return true;
}

Image MotionVectors(const Scene &scene, const Camera &camera, const Camera &previous,
                    const Camera &next, int width, int height) {
    Image motion(width, height, 4);
    Camera pinhole = camera;
    pinhole.lensRadius = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double cx = x + 0.5, cy = y + 0.5;
            Ray ray = pinhole.Generate(cx, cy, width, height, 0, 0);
            Hit hit;
            if (!scene.Intersect(ray, std::numeric_limits<double>::infinity(), &hit)) continue;
            double px, py, nx, ny;
            if (!Project(previous, hit.position, width, height, &px, &py) ||
                !Project(next, hit.position, width, height, &nx, &ny))
                continue;
            motion.At(0, y, x) = float(px - cx);
            motion.At(1, y, x) = float(cy - py);
            motion.At(2, y, x) = float(cx - nx);
            motion.At(3, y, x) = float(ny - cy);
        }
    return motion;
}

}  // namespace mcd::render
