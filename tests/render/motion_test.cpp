// The renderer's camera path and motion vectors (tools/render/motion.h): Project inverts
// Camera::Generate, and the vectors of consecutive frames lead to the same surface point:
// where a pixel of frame f lands in frame f + 1 by its forward vector, frame f + 1's
// backward vector there leads back to it.
#include <gtest/gtest.h>

#include <cmath>

#include "tools/render/motion.h"

namespace mcd::test {
namespace {

using render::Camera;
using render::Vec3;

TEST(RenderMotion, ProjectInvertsGenerate) {
    render::Scene scene = render::BuildScene("cornell");
    const int w = 37, h = 23;
    for (double y : {0.5, 7.25, 22.9})
        for (double x : {0.1, 18.5, 36.75}) {
            render::Ray ray = scene.camera.Generate(x, y, w, h, 0, 0);
            double px = 0, py = 0;
            ASSERT_TRUE(render::Project(scene.camera, ray.origin + ray.direction * 3.7, w, h,
                                        &px, &py));
            EXPECT_NEAR(px, x, 1e-9);
            EXPECT_NEAR(py, y, 1e-9);
        }
    double px, py;
    EXPECT_FALSE(render::Project(scene.camera, scene.camera.eye * 2 - scene.camera.target, w, h,
                                 &px, &py));
}

TEST(RenderMotion, ConsecutiveFramesAgree) {
    render::Scene scene = render::BuildScene("cornell");
    const Vec3 step{0.2, 0.05, 0};
    const int w = 32, h = 24;
    Camera c0 = scene.camera, c1 = render::CameraAt(scene.camera, step, 1);
    Image m0 = render::MotionVectors(scene, c0, render::CameraAt(c0, step, -1), c1, w, h);
    Image m1 = render::MotionVectors(scene, c1, c0, render::CameraAt(c0, step, 2), w, h);
    int checked = 0, moved = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Forward: next = (x - Z, y + W), pixel centres.
            double nx = x + 0.5 - m0.At(2, y, x), ny = y + 0.5 + m0.At(3, y, x);
            int ix = int(std::floor(nx)), iy = int(std::floor(ny));
            if (ix < 1 || iy < 1 || ix >= w - 1 || iy >= h - 1) continue;
            moved += std::hypot(m0.At(2, y, x), m0.At(3, y, x)) > 0.5;
            // Back from the pixel it lands in: previous = (x + X, y - Y), off by at most the
            // distance to that pixel's centre (a flat wall: the vectors vary smoothly).
            double bx = ix + 0.5 + m1.At(0, iy, ix), by = iy + 0.5 - m1.At(1, iy, ix);
            double slack = std::hypot(nx - (ix + 0.5), ny - (iy + 0.5)) * 1.5 + 1e-3;
            if (std::hypot(bx - (x + 0.5), by - (y + 0.5)) <= slack) ++checked;
        }
    EXPECT_GT(moved, w * h / 2) << "the camera moves more than half a pixel";
    // Where depth jumps (an object's edge) the two points differ; everywhere else agree.
    EXPECT_GT(checked, w * h * 8 / 10);
}

}  // namespace
}  // namespace mcd::test
