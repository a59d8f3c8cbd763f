// The caller's buffers (LayerView, OutputView): checking a view and copying between one
// and a planar mcd::Image, float32 or half, by its strides.
#pragma once

#include <string>

#include "mcdenoise/frame.h"
#include "mcdenoise/image.h"
#include "mcdenoise/view.h"

namespace mcd::api {

// Throws mcd::Error (invalid argument) naming `what` unless the view has a pointer, a size
// and channels of at least 1 and a known data type.
template <class Pointer>
void CheckView(const BasicView<Pointer> &view, const std::string &what);

// Write `image` (planar, the view's size) into channels [first, first + image.channels)
// of `view`, converting to its data type.
void WriteView(const Image &image, const OutputView &view, int first = 0);

// Throws mcd::Error (invalid argument) unless `output` can take a run's result on `frame`:
// the frame's size, and the color's channels or one more (alpha).
void CheckOutput(const Frame &frame, const OutputView &output);

// Write a run's result into `output`: `color`'s channels, then `alpha` (1 where it is
// empty) when the view has one channel more.
void WriteOutput(const Image &color, const Image &alpha, const OutputView &output);

}  // namespace mcd::api
