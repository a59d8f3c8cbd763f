#include "cpu_reference/pivot_spikes.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {
namespace {

// The lower middle of f over the 8 neighbours of (x, y) inside a w x h image.
template <typename F>
double LowerMiddle(int w, int h, int x, int y, F f) {
    std::vector<double> values;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if ((dx != 0 || dy != 0) && xx >= 0 && yy >= 0 && xx < w && yy < h)
                values.push_back(f(xx, yy));
        }
    std::sort(values.begin(), values.end());
    return values[(values.size() - 1) / 2];
}

}  // namespace

std::vector<size_t> ScalePivotSpikes(const Image &color, const Image &pivot,
                                     const Image &variance, Image *output) {
    const int w = color.width, h = color.height;
    // The pivot's channel sum in float, as a frame holds it.
    auto sum = [&](int x, int y) {
        float s = 0;
        for (int c = 0; c < pivot.channels; ++c) s += pivot.At(c, y, x);
        return s;
    };
    std::vector<size_t> changed;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool finite = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (xx >= 0 && yy >= 0 && xx < w && yy < h && !std::isfinite(sum(xx, yy)))
                        finite = false;
                }
            if (!finite || w * h == 1) continue;  // no neighbours
            double m = LowerMiddle(w, h, x, y, [&](int u, int v) { return double(sum(u, v)); });
            if (!(m > 0) || !(sum(x, y) > 16 * m)) continue;  // no level to scale to
            int over = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if ((dx != 0 || dy != 0) && xx >= 0 && yy >= 0 && xx < w && yy < h &&
                        sum(xx, yy) > 16 * m)
                        ++over;
                }
            if (over >= 2) continue;
            double c = 0, v = 0;
            bool good = true;
            for (int k = 0; k < color.channels; ++k) {
                c += color.At(k, y, x);
                double vk = variance.At(variance.channels == 1 ? 0 : k, y, x);
                if (!std::isfinite(vk) || vk < 0) good = false;
                v += vk;
            }
            if (!good || !(c > 0) || std::sqrt(v) < 0.25 * c) continue;
            bool any = false;
            for (int k = 0; k < color.channels; ++k) {
                int pc = pivot.channels == 1 ? 0 : k;
                double own = pivot.At(pc, y, x);
                if (output->At(k, y, x) == color.At(k, y, x) || !(own > 0)) continue;
                double mk = LowerMiddle(
                    w, h, x, y, [&](int u, int vv) { return double(pivot.At(pc, vv, u)); });
                if (!(mk > 0)) continue;
                output->At(k, y, x) = float(double(output->At(k, y, x)) * (mk / own));
                any = true;
            }
            if (any) changed.push_back(size_t(y) * w + x);
        }
    return changed;
}

std::vector<size_t> KeepPivotSpikeClusters(const Image &color, const Image &pivot,
                                           Image *output) {
    const int w = color.width, h = color.height;
    auto sum = [&](int x, int y) {
        float s = 0;
        for (int c = 0; c < pivot.channels; ++c) s += pivot.At(c, y, x);
        return s;
    };
    std::vector<size_t> changed;
    if (w * h == 1) return changed;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool finite = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (xx >= 0 && yy >= 0 && xx < w && yy < h && !std::isfinite(sum(xx, yy)))
                        finite = false;
                }
            if (!finite) continue;
            double m = LowerMiddle(w, h, x, y, [&](int u, int v) { return double(sum(u, v)); });
            if (!(m > 0) || !(sum(x, y) > 16 * m)) continue;
            int over = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if ((dx != 0 || dy != 0) && xx >= 0 && yy >= 0 && xx < w && yy < h &&
                        sum(xx, yy) > 16 * m)
                        ++over;
                }
            if (over < 2) continue;
            bool any = false;
            for (int k = 0; k < color.channels; ++k) {
                float in = color.At(k, y, x);
                if (!std::isfinite(in) || output->At(k, y, x) == in) continue;
                output->At(k, y, x) = in;
                any = true;
            }
            if (any) changed.push_back(size_t(y) * w + x);
        }
    return changed;
}

}  // namespace mcd::ref
