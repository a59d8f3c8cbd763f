#include "cpu_reference/input_minimum.h"

#include <cmath>

namespace mcd::ref {

size_t RaiseToInputMinimum(const Image &input, int r, Image *output) {
    size_t changed = 0;
    for (int c = 0; c < input.channels; ++c)
        for (int y = 0; y < input.height; ++y)
            for (int x = 0; x < input.width; ++x) {
                float o = output->At(c, y, x);
                bool finite = std::isfinite(o);
                float low = input.At(c, y, x);
                for (int v = y - r; v <= y + r; ++v)
                    for (int u = x - r; u <= x + r; ++u) {
                        if (v < 0 || v >= input.height || u < 0 || u >= input.width) continue;
                        float in = input.At(c, v, u);
                        finite = finite && std::isfinite(in);
                        if (in < low) low = in;
                    }
                if (finite && o < low) {
                    output->At(c, y, x) = low;
                    ++changed;
                }
            }
    return changed;
}

}  // namespace mcd::ref
