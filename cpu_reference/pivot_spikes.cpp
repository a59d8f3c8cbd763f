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

// s(x, y): the pivot's channel sum in float, as a frame holds it.
float PivotSum(const Image &pivot, int x, int y) {
    float s = 0;
    for (int c = 0; c < pivot.channels; ++c) s += pivot.At(c, y, x);
    return s;
}

// Where (x, y) and its neighbours' s are finite and s(x, y) is over 16 x m, m the lower
// middle of the neighbours' s, m > 0: how many neighbours' s are over 16 x m too, m in *m;
// -1 otherwise (no neighbours either).
int SpikeNeighbours(const Image &pivot, int x, int y, double *m) {
    const int w = pivot.width, h = pivot.height;
    if (w * h == 1) return -1;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < w && yy < h &&
                !std::isfinite(PivotSum(pivot, xx, yy)))
                return -1;
        }
    *m = LowerMiddle(w, h, x, y, [&](int u, int v) { return double(PivotSum(pivot, u, v)); });
    if (!(*m > 0) || !(PivotSum(pivot, x, y) > 16 * *m)) return -1;
    int over = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if ((dx != 0 || dy != 0) && xx >= 0 && yy >= 0 && xx < w && yy < h &&
                PivotSum(pivot, xx, yy) > 16 * *m)
                ++over;
        }
    return over;
}

}  // namespace

std::vector<size_t> ScalePivotSpikes(const Image &color, const Image &pivot,
                                     const Image &variance, Image *output) {
    const int w = color.width, h = color.height;
    std::vector<size_t> changed;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double m = 0;
            int over = SpikeNeighbours(pivot, x, y, &m);
            if (over < 0 || over >= 2) continue;
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
                                           const Image *objectId, const Image *partId,
                                           Image *output) {
    const int w = color.width, h = color.height;
    auto id = [](const Image *layer, int x, int y) {
        return layer ? layer->At(0, y, x) : 0.0f;
    };
    std::vector<size_t> changed;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double m = 0;
            if (SpikeNeighbours(pivot, x, y, &m) < 2) continue;
            // The neighbours not over 16 x m must have (x, y)'s ids.
            bool sameIds = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h ||
                        PivotSum(pivot, xx, yy) > 16 * m)
                        continue;
                    if (id(objectId, xx, yy) != id(objectId, x, y) ||
                        id(partId, xx, yy) != id(partId, x, y))
                        sameIds = false;
                }
            if (!sameIds) continue;
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
