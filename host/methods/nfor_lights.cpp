#include "host/methods/nfor_lights.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "host/methods/nfor_emitters.h"

namespace mcd {

size_t NforSpreadLights(const Image &albedo, const Image *alpha, const NforLightSettings &s,
                        Image *output) {
    const Image in = *output;
    const int w = in.width, h = in.height;
    const size_t n = in.PixelCount();
    // Per pixel: the share it gives each neighbour, -1 where it is no emitter, 0 where it
    // takes no part (fully transparent).
    std::vector<double> share(n, -1.0);
    for (size_t i = 0; i < n; ++i) {
        if (alpha && !(alpha->data[i] > 0.f)) {
            share[i] = 0;
            continue;
        }
        const float most = NforLargestAlbedo(albedo, i);
        if (!(most > s.emitterAlbedo)) continue;
        share[i] = double(most < s.weakAlbedo ? s.weakShare : s.strongShare);
    }
    std::vector<double> delta(in.Size(), 0.0);
    size_t giving = 0;
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (!(share[p] > 0)) continue;
            bool finite = true;
            for (int c = 0; c < in.channels; ++c)
                finite = finite && std::isfinite(in.Plane(c)[p]);
            if (!finite) continue;
            bool gave = false;
            for (int k = 0; k < 4; ++k) {
                const int u = x + dx[k], v = y + dy[k];
                if (u < 0 || v < 0 || u >= w || v >= h) continue;
                const size_t q = size_t(v) * w + u;
                if (share[q] >= 0) continue;
                for (int c = 0; c < in.channels; ++c) {
                    const double given = share[p] * double(in.Plane(c)[p]);
                    delta[size_t(c) * n + q] += given;
                    delta[size_t(c) * n + p] -= given;
                }
                gave = true;
            }
            giving += gave;
        }
    for (size_t i = 0; i < in.Size(); ++i)
        if (delta[i] != 0) output->data[i] = float(double(in.data[i]) + delta[i]);
    return giving;
}

}  // namespace mcd
