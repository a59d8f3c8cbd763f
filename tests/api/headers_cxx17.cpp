// The installed C++ headers on their own, compiled as C++17 with -pedantic -Werror
// (target mcd_header_check): a C++20 feature or an internal header here fails the build.
#include <mcdenoise/error.h>
#include <mcdenoise/frame.h>
#include <mcdenoise/image.h>
#include <mcdenoise/io.h>
#include <mcdenoise/io_c.h>
#include <mcdenoise/mcdenoise.h>
#include <mcdenoise/mcdenoise_c.h>
#include <mcdenoise/view.h>

static_assert(__cplusplus == 201703L, "built as C++17");

// Every declaration is usable, not only parsed.
[[maybe_unused]] static mcd::Result RunOnView(mcd::Device &device, const float *rgb,
                                              float *out) {
    mcd::Frame frame;
    frame.SetLayer("color", mcd::LayerView::Interleaved(rgb, 4, 4, 3));
    mcd::RunOptions run;
    run.output = mcd::OutputView::Interleaved(out, 4, 4, 3);
    run.cancel = [] { return false; };
    return mcd::Method("auto").Run(device, frame, run);
}
