// Ershov's tracing filter (section 5): the gather of eq. 15 with the self weight of eq. 16,
// the re-weighting of eq. 14 and the inter-pixel weight of eq. 17. One invocation per output
// pixel walks the disk of neighbours, with loop bounds the same for every lane, for the sum
// of the fixed parts (C_p), then once per TRACING_OWN_CHUNK own samples for their self
// weights, then for the neighbours' samples re-weighted for the pixel.
#ifndef MCD_SHADERS_TRACING_GATHER_H
#define MCD_SHADERS_TRACING_GATHER_H

// Read-only float texel buffers (the recorder binds at most 8 buffers). SURFACES holds
// TRACING_SURFACE_PLANES planes of rows x width floats, plane k of pixel (y, x) at
// k * rows * width + y * width + x. DIRECTION, RADIANCE and OWN hold 3 fields (x y z, r g b)
// and PDF one, each field spp planes: field f of sample s of pixel (y, x) at
// ((f * spp + s) * rows + y) * width + x (y relative to the records' first row).
#define TRACING_GATHER_SURFACES 0
#define TRACING_GATHER_DIRECTION 1
#define TRACING_GATHER_PDF 2
#define TRACING_GATHER_RADIANCE 3
#define TRACING_GATHER_OWN 4
// Storage buffer: 3 planes of outRows x width floats.
#define TRACING_GATHER_OUT 5
#define TRACING_GATHER_BINDINGS 6

// Surface planes: normal xyz, wo xyz, diffuse rgb, glossy rgb, kappa, valid.
#define TRACING_SURF_NORMAL 0
#define TRACING_SURF_WO 3
#define TRACING_SURF_DIFFUSE 6
#define TRACING_SURF_GLOSSY 9
#define TRACING_SURF_KAPPA 12
#define TRACING_SURF_VALID 13
#define TRACING_SURFACE_PLANES 14

#define TRACING_LOCAL_SIZE 64
// Own samples held in private arrays while the disk is walked for their self weights.
#define TRACING_OWN_CHUNK 16

#ifdef __cplusplus
namespace mcd::shader {
struct TracingGatherPush {
#else
layout(push_constant) uniform TracingGatherPush {
#endif
    int width;
    int rows;  // rows of records
    int spp;
    int radius;   // the disk's radius in pixels, >= 0
    int outRow0;  // first output row, relative to the records' first row
    int outRows;
    int pixelBase;   // first output pixel (outRow * width + x) of this dispatch
    int pixelCount;  // output pixels of this dispatch
    float alpha;
    float beta;
    float gamma;
    float selfFloor;
#ifdef __cplusplus
};
static_assert(sizeof(TracingGatherPush) == 48);
}  // namespace mcd::shader
#else
}
push;
#endif

#endif
