// The tracing filter's parameters (Ershov et al., section 5), as the GPU gather
// (host/kernels/tracing_gather.h), the CPU reference (cpu_reference/tracing_filter.h), the
// renderer (tools/render/renderer.h) and `mcdenoise render --tf-*` read them: a layout,
// like a kernel's push-constant header. The initializers are the defaults the command line
// shows.
#pragma once

namespace mcd {

// Eq. 17: w(p <- p', u) = C_p exp(-alpha |p - p'|^2) exp(-beta (1 - n.n')) exp(-gamma F^2),
// over the neighbours p' != p with |p - p'| <= radius (a disk, in pixels) that see a
// smooth surface. C_p = min(1, selfFloor / sum of the fixed parts) keeps the self weight
// of eq. 16 at least 1 - selfFloor.
struct TracingParams {
    int radius = 3;  // most of a wide radius's gain at a fraction of the gather (measured)
    float alpha = 0.02f, beta = 20.f, gamma = 0.f;
    // The paper keeps the self weight at least 1/2 (selfFloor 0.5); 0.9 measured a lower
    // relMSE at the same time and mean brightness (docs/renderer.md), so it
    // is the default.
    float selfFloor = 0.9f;
};

}  // namespace mcd
