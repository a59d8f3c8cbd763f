// A camera path for the built-in renderer's sequences (docs/sequences.md): the camera
// trucked by a fixed step a frame, and the motion vectors of a frame as Blender Cycles
// writes its Vector pass (shaders/temporal/temporal.h), so that `denoise` follows a moving
// camera through the frames of either renderer alike.
#pragma once

#include "host/image.h"
#include "tools/render/scene.h"

namespace mcd::render {

// The camera of frame `frame`: its eye and target moved by frame x step.
Camera CameraAt(const Camera &camera, const Vec3 &step, double frame);

// Where world point p lies in the camera's image, in pixels (x right, y down, pixel (x, y)
// covering [x, x+1) x [y, y+1)); false where it lies behind the camera. A pinhole: a lens's
// blur is left out, as the Vector pass leaves it.
bool Project(const Camera &camera, const Vec3 &p, int width, int height, double *x, double *y);

// The Vector pass of a frame seen through `camera`, the frames before and after seen
// through `previous` and `next`: per pixel, the surface point at its centre projected into
// each; 4 planes, (X, Y) = position in the previous frame minus position in this one,
// (Z, W) = position in this frame minus position in the next, in pixels, y up; 0 where the
// centre sees no surface (Blender's background) or the point is behind a camera. The
// scene is still: only the camera moves.
Image MotionVectors(const Scene &scene, const Camera &camera, const Camera &previous,
                    const Camera &next, int width, int height);

}  // namespace mcd::render
