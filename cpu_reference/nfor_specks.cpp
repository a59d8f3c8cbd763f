#include "cpu_reference/nfor_specks.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcd::ref {

namespace {

double Mean(const Image &image, int x, int y) {
    double sum = 0;
    for (int c = 0; c < image.channels; ++c) sum += image.At(c, y, x);
    return sum / image.channels;
}

}  // namespace

void NforClampSpecks(const Image &mask, int rank, double relative, double floor, Image *output,
                     double flatShare, double flatRelative) {
    const Image before = *output;
    for (int y = 0; y < before.height; ++y)
        for (int x = 0; x < before.width; ++x) {
            if (mask.At(0, y, x) != 1) continue;
            std::vector<double> neighbours;
            bool emitter = false, finite = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int u = x + dx, v = y + dy;
                    if ((dx == 0 && dy == 0) || u < 0 || v < 0 || u >= before.width ||
                        v >= before.height)
                        continue;
                    if (mask.At(0, v, u) == 0) emitter = true;
                    double l = Mean(before, u, v);
                    if (!std::isfinite(l)) finite = false;
                    neighbours.push_back(l);
                }
            if (emitter || !finite || neighbours.size() < 8) continue;
            std::sort(neighbours.begin(), neighbours.end());
            double n = neighbours[neighbours.size() - size_t(rank)];
            // The 5th brightest of the 8: the neighbours' median, on a flat ground near n.
            bool flat = flatShare > 0 && neighbours[3] >= flatShare * n;
            double bound = (1 + (flat ? flatRelative : relative)) * n + floor,
                   l = Mean(before, x, y);
            if (!(l > bound)) continue;
            for (int c = 0; c < before.channels; ++c)
                output->At(c, y, x) = float(before.At(c, y, x) * (bound / l));
        }
}

}  // namespace mcd::ref
