#include "harness/gpu_auto.h"

#include "host/kernels/auto_smooth.h"
#include "host/vk/gpu_image.h"
#include "host/vk/recorder.h"

namespace mcd::test {

Image GpuSmooth(vk::Context &ctx, const Image &errors, int radius) {
    vk::GpuImage in(ctx, errors.width, errors.height, errors.channels, "e");
    vk::GpuImage out(ctx, errors.width, errors.height, errors.channels, "s");
    vk::GpuImage rows(ctx, errors.width, errors.height, 2 * errors.channels, "rows");
    in.Upload(errors);
    vk::Recorder recorder(ctx);
    RecordAutoSmooth(ctx, recorder, in, radius, rows, out);
    recorder.Submit();
    return out.Download();
}

}  // namespace mcd::test
