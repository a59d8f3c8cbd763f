// Run method auto's window kernels on an image and bring the result back: one submit each.
#pragma once

#include "host/image.h"
#include "host/vk/context.h"

namespace mcd::test {

// The tents' window means of every plane (RecordAutoSmooth).
Image GpuSmooth(vk::Context &ctx, const Image &errors, int radius);

}  // namespace mcd::test
