// Ershov's tracing filter (section 5) on the GPU: the gather of eqs. 14-17 over a band of
// rows of records (shaders/tracing/gather.comp). The CPU twin is ref::TracingFilter.
#pragma once

#include <memory>
#include <vector>

#include "host/tracing.h"

namespace mcd {

namespace vk {
class Context;
}

class TracingGather {
  public:
    // Built once per context and reused for many bands: the kernel is compiled on the first
    // Run and the record buffers grow to the largest band seen.
    explicit TracingGather(vk::Context &context);
    ~TracingGather();
    TracingGather(const TracingGather &) = delete;
    TracingGather &operator=(const TracingGather &) = delete;

    // The filtered part of rows [outY0, outY0 + outRows) (frame rows inside the records),
    // 3 floats per pixel, row-major: the same contract as ref::TracingFilter. Throws
    // mcd::Error naming the band and its size when the records do not fit one binding
    // (see MaxRecordRows) and for inconsistent records or parameters.
    std::vector<float> Run(const TracingRecords &records, const TracingParams &params,
                           int outY0, int outRows);

    // The most rows of records one band `width` pixels wide with `spp` samples per pixel may
    // hold on this device (each per-sample vector field is one binding of 3 x spp x rows x
    // width floats). A band for output rows [y0, y0 + n) needs the records of n + 2 radius rows
    // (fewer at the frame's edges). 0 when not even one row fits.
    int MaxRecordRows(int width, int spp) const;

    // GPU time of the last Run's dispatches in milliseconds (negative without timestamps).
    double LastGpuMs() const { return lastGpuMs; }

  private:
    struct Buffers;
    vk::Context &context;
    std::unique_ptr<Buffers> buffers;
    double lastGpuMs = 0;
};

}  // namespace mcd
