#include "host/methods/nfor_line.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace mcd {

namespace {

// The window of the frame the pass works on: every light and the reach around it.
struct Window {
    int x0 = 0, y0 = 0, w = 0, h = 0;
    size_t Index(int x, int y) const { return size_t(y) * w + x; }
};

// A plane of the window, in double.
using Plane = std::vector<double>;

// An index mirrored at the ends without repeating the end (d c b | a b c d).
int Mirror(int i, int n) {
    if (n == 1) return 0;
    const int period = 2 * (n - 1);
    i %= period;
    if (i < 0) i += period;
    return i < n ? i : period - i;
}

// A Gaussian blur of standard deviation sigma (radius ceil(3 sigma)), rows then columns.
Plane Blur(const Plane &in, const Window &win, double sigma) {
    const int r = int(std::ceil(3 * sigma));
    std::vector<double> k(size_t(2 * r + 1));
    double total = 0;
    for (int i = -r; i <= r; ++i)
        total += k[size_t(i + r)] = std::exp(-i * i / (2 * sigma * sigma));
    for (double &v : k) v /= total;
    Plane rows(in.size()), out(in.size());
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x) {
            double sum = 0;
            for (int i = 0; i <= 2 * r; ++i)
                sum += k[size_t(i)] * in[win.Index(Mirror(x + i - r, win.w), y)];
            rows[win.Index(x, y)] = sum;
        }
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x) {
            double sum = 0;
            for (int i = 0; i <= 2 * r; ++i)
                sum += k[size_t(i)] * rows[win.Index(x, Mirror(y + i - r, win.h))];
            out[win.Index(x, y)] = sum;
        }
    return out;
}

// A plane's value at (px, py) interpolated bilinearly, 0 outside the window.
double Bilinear(const Plane &a, const Window &win, double px, double py) {
    const double fx0 = std::floor(px), fy0 = std::floor(py);
    const double fx = px - fx0, fy = py - fy0;
    const int x0 = int(fx0), y0 = int(fy0);
    auto at = [&](int x, int y) {
        return x < 0 || y < 0 || x >= win.w || y >= win.h ? 0.0 : a[win.Index(x, y)];
    };
    return at(x0, y0) * (1 - fx) * (1 - fy) + at(x0 + 1, y0) * fx * (1 - fy) +
           at(x0, y0 + 1) * (1 - fx) * fy + at(x0 + 1, y0 + 1) * fx * fy;
}

// Rec. 709 luminance of a pixel (the first channel where there are fewer than 3).
double RawLuminance(const Image &image, size_t i) {
    return image.channels >= 3 ? 0.2126 * image.Plane(0)[i] + 0.7152 * image.Plane(1)[i] +
                                     0.0722 * image.Plane(2)[i]
                               : double(image.Plane(0)[i]);
}

// The same, 0 where it is not finite.
double Luminance(const Image &image, size_t i) {
    const double l = RawLuminance(image, i);
    return std::isfinite(l) ? l : 0.0;
}

double Luminance(const std::vector<double> &rgb) {
    return rgb.size() >= 3 ? 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2] : rgb[0];
}

// Whether a pixel is a light: any albedo channel above the gate (a NaN channel hides none).
bool IsLight(const Image &albedo, size_t p, float gate) {
    for (int c = 0; c < albedo.channels; ++c)
        if (albedo.Plane(c)[p] > gate) return true;
    return false;
}

// Whether some pixel within `margin` (Chebyshev) of each pixel is set, by a running count
// along rows, then columns.
std::vector<char> Dilate(const std::vector<char> &mask, int w, int h, int margin) {
    std::vector<char> rows(mask.size()), out(mask.size());
    auto pass = [&](const std::vector<char> &in, std::vector<char> &to, int n, int lines,
                    auto index) {
        for (int l = 0; l < lines; ++l) {
            int count = 0;
            for (int i = 0; i < std::min(n, margin); ++i) count += in[index(i, l)];
            for (int i = 0; i < n; ++i) {
                if (i + margin < n) count += in[index(i + margin, l)];
                if (i - margin - 1 >= 0) count -= in[index(i - margin - 1, l)];
                to[index(i, l)] = count > 0;
            }
        }
    };
    pass(mask, rows, w, h, [&](int i, int l) { return size_t(l) * w + i; });
    pass(rows, out, h, w, [&](int i, int l) { return size_t(i) * w + l; });
    return out;
}

// The windows the pass works on: the lights and the reach around them, one per connected
// group of that reach, groups whose boxes overlap merged; none where no pixel is a light.
// A pixel the pass reads or writes lies in one window alone, so the windows give the bits
// of one window around every light, at the cost of the lights' surroundings alone.
std::vector<Window> FindWindows(const Image &albedo, const NforLineSettings &s) {
    const int w = albedo.width, h = albedo.height;
    std::vector<char> light(albedo.PixelCount());
    bool any = false;
    for (size_t p = 0; p < light.size(); ++p)
        any |= light[p] = IsLight(albedo, p, s.lightAlbedo);
    std::vector<Window> windows;
    if (!any) return windows;
    std::vector<char> reach = Dilate(light, w, h, s.gateReach + s.radius + 2 + kNforLineReach);
    std::vector<size_t> stack;
    for (size_t start = 0; start < reach.size(); ++start) {
        if (!reach[start]) continue;
        int lo[2] = {w, h}, hi[2] = {-1, -1};
        reach[start] = 0, stack.push_back(start);
        while (!stack.empty()) {
            const size_t p = stack.back();
            stack.pop_back();
            const int x = int(p % size_t(w)), y = int(p / size_t(w));
            lo[0] = std::min(lo[0], x), hi[0] = std::max(hi[0], x);
            lo[1] = std::min(lo[1], y), hi[1] = std::max(hi[1], y);
            for (auto [u, v] : {std::pair{x - 1, y}, std::pair{x + 1, y}, std::pair{x, y - 1},
                                std::pair{x, y + 1}})
                if (u >= 0 && v >= 0 && u < w && v < h && reach[size_t(v) * w + u])
                    reach[size_t(v) * w + u] = 0, stack.push_back(size_t(v) * w + u);
        }
        windows.push_back({lo[0], lo[1], hi[0] + 1 - lo[0], hi[1] + 1 - lo[1]});
    }
    // Merge windows whose boxes overlap until none do.
    for (bool merged = true; merged;) {
        merged = false;
        for (size_t a = 0; a < windows.size() && !merged; ++a)
            for (size_t b = a + 1; b < windows.size() && !merged; ++b) {
                Window &p = windows[a], &q = windows[b];
                if (p.x0 >= q.x0 + q.w || q.x0 >= p.x0 + p.w || p.y0 >= q.y0 + q.h ||
                    q.y0 >= p.y0 + p.h)
                    continue;
                const int x1 = std::max(p.x0 + p.w, q.x0 + q.w),
                          y1 = std::max(p.y0 + p.h, q.y0 + q.h);
                p.x0 = std::min(p.x0, q.x0), p.y0 = std::min(p.y0, q.y0);
                p.w = x1 - p.x0, p.h = y1 - p.y0;
                windows.erase(windows.begin() + std::ptrdiff_t(b));
                merged = true;
            }
    }
    return windows;
}

// The line's direction per pixel of the window (the structure tensor's minor eigenvector),
// across it (its major one), and whether the tensor holds any structure.
struct LineField {
    Plane smooth, alongX, alongY, acrossX, acrossY;
    std::vector<char> structured;
};

LineField Tensor(const Plane &lum, const Window &win) {
    LineField f;
    f.smooth = Blur(lum, win, 1.0);
    Plane xx(lum.size()), yy(lum.size()), xy(lum.size());
    auto diff = [&](int x, int y, int dx, int dy, int n, int i) {
        if (n == 1) return 0.0;
        const int lo = i == 0 ? 0 : i - 1, hi = i == n - 1 ? n - 1 : i + 1;
        const double a = f.smooth[win.Index(dx ? lo : x, dy ? lo : y)],
                     b = f.smooth[win.Index(dx ? hi : x, dy ? hi : y)];
        return (b - a) / (hi - lo);
    };
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x) {
            const double gx = diff(x, y, 1, 0, win.w, x), gy = diff(x, y, 0, 1, win.h, y);
            const size_t i = win.Index(x, y);
            xx[i] = gx * gx, yy[i] = gy * gy, xy[i] = gx * gy;
        }
    xx = Blur(xx, win, 3.0), yy = Blur(yy, win, 3.0), xy = Blur(xy, win, 3.0);
    const size_t n = lum.size();
    f.alongX.resize(n), f.alongY.resize(n), f.acrossX.resize(n), f.acrossY.resize(n);
    f.structured.resize(n);
    for (size_t i = 0; i < n; ++i) {
        const double trace = xx[i] + yy[i];
        const double disc =
            std::sqrt(std::max((xx[i] - yy[i]) * (xx[i] - yy[i]) / 4 + xy[i] * xy[i], 0.0));
        const double coherence = trace > 0 ? std::pow(2 * disc / std::max(trace, 1e-30), 2) : 0;
        f.structured[i] = coherence > 0;
        const double angle = 0.5 * std::atan2(2 * xy[i], xx[i] - yy[i]);
        f.acrossX[i] = std::cos(angle), f.acrossY[i] = std::sin(angle);
        f.alongX[i] = -f.acrossY[i], f.alongY[i] = f.acrossX[i];
    }
    return f;
}

// A plane's mean over the 5 steps -2..2 along the pixel's line.
double LineMean(const Plane &a, const LineField &f, const Window &win, int x, int y) {
    const size_t i = win.Index(x, y);
    double sum = 0;
    for (int t = -2; t <= 2; ++t)
        sum += Bilinear(a, win, x + t * f.alongX[i], y + t * f.alongY[i]);
    return sum / 5;
}

// Whether a pixel lies on a line: the smoothed luminance 1 and 2 steps along it above
// ratio x the luminance 2 steps across.
bool OnLine(const LineField &f, const Window &win, int x, int y, double ratio) {
    const size_t i = win.Index(x, y);
    if (!f.structured[i]) return false;
    double along = 0;
    for (int t : {-2, -1, 1, 2})
        along += Bilinear(f.smooth, win, x + t * f.alongX[i], y + t * f.alongY[i]);
    const double across =
        (Bilinear(f.smooth, win, x - 2 * f.acrossX[i], y - 2 * f.acrossY[i]) +
         Bilinear(f.smooth, win, x + 2 * f.acrossX[i], y + 2 * f.acrossY[i])) /
        2;
    return along / 4 > ratio * across;
}

// The cap: each pixel of the window adds what it was given (`add`, channel planes of the
// window), at most what lifts its output's luminance to the input's mean along its line.
// Returns the luminance dropped.
double AddCapped(const std::vector<double> &add, const Plane &inputLum, const LineField &f,
                 const Window &win, Image *output) {
    const int ch = output->channels;
    const size_t n = size_t(win.w) * win.h;
    double dropped = 0;
    std::vector<double> given(size_t(ch), 0.0);
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x) {
            const size_t i = win.Index(x, y),
                         p = size_t(y + win.y0) * output->width + x + win.x0;
            for (int c = 0; c < ch; ++c) given[size_t(c)] = add[size_t(c) * n + i];
            const double received = Luminance(given);
            if (!(received > 0)) continue;
            const double before = RawLuminance(*output, p);
            if (!std::isfinite(before)) continue;
            const double room = std::max(LineMean(inputLum, f, win, x, y) - before, 0.0);
            const double kept = std::min(1.0, room / std::max(received, 1e-12));
            for (int c = 0; c < ch; ++c)
                output->Plane(c)[p] =
                    float(double(output->Plane(c)[p]) + given[size_t(c)] * kept);
            dropped += received * (1 - kept);
        }
    return dropped;
}

}  // namespace

bool NforLineSpreads(const Image &albedo, float lightAlbedo) {
    if (!(lightAlbedo > 0)) return false;
    for (size_t i = 0; i < albedo.PixelCount(); ++i)
        if (IsLight(albedo, i, lightAlbedo)) return true;
    return false;
}

namespace {

// The pass within one window, its figures added to `stats`.
void SpreadWindow(const Image &color, const Image &clamped, const Image &albedo,
                  const Image *alpha, const NforLineSettings &s, const Window &win,
                  Image *output, NforLineStats *total) {
    NforLineStats &stats = *total;
    const int W = color.width, ch = color.channels;
    const size_t n = size_t(win.w) * win.h;
    auto frame = [&](int x, int y) { return size_t(y + win.y0) * W + (x + win.x0); };
    auto present = [&](int x, int y) { return !alpha || alpha->data[frame(x, y)] > 0.f; };
    // The window's luminances, the lights and the pixels near one (rows, then columns).
    Plane lum(n), inputLum(n), positive(n);
    std::vector<char> light(n), rows(n), near(n);
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x) {
            const size_t i = win.Index(x, y), p = frame(x, y);
            lum[i] = Luminance(clamped, p), inputLum[i] = Luminance(color, p);
            positive[i] = std::max(lum[i], 0.0);
            light[i] = IsLight(albedo, p, s.lightAlbedo);
        }
    const int g = s.gateReach;
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x)
            for (int u = std::max(0, x - g); u <= std::min(win.w - 1, x + g); ++u)
                rows[win.Index(x, y)] |= light[win.Index(u, y)];
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x)
            for (int v = std::max(0, y - g); v <= std::min(win.h - 1, y + g); ++v)
                near[win.Index(x, y)] |= rows[win.Index(x, v)];
    const LineField f = Tensor(lum, win);
    // Each target's weight: the clamped luminance averaged along its own line.
    Plane lineWeight(n, -1.0);
    auto weightAt = [&](int x, int y) {
        double &m = lineWeight[win.Index(x, y)];
        if (m < 0) m = std::max(LineMean(positive, f, win, x, y), 0.0);
        return m;
    };
    std::vector<double> add(n * size_t(ch), 0.0), removed(size_t(ch), 0.0);
    std::vector<std::pair<size_t, double>> targets;
    const double bandDenominator = 2 * 0.7 * 0.7;
    for (int y = 0; y < win.h; ++y)
        for (int x = 0; x < win.w; ++x) {
            const size_t i = win.Index(x, y), p = frame(x, y);
            if (!near[i] || !present(x, y)) continue;
            bool finite = true, any = false;
            for (int c = 0; c < ch; ++c) {
                removed[size_t(c)] =
                    std::max(double(color.Plane(c)[p]) - clamped.Plane(c)[p], 0.0);
                finite = finite && std::isfinite(removed[size_t(c)]);
                any = any || removed[size_t(c)] > 0;
            }
            if (!finite || !any || !OnLine(f, win, x, y, s.ratio)) continue;
            // The targets: steps along the line, one either side across it, to the nearest
            // pixel; a pixel reached twice sums its weights.
            targets.clear();
            double total = 0;
            for (int t = -s.radius; t <= s.radius; ++t)
                for (int b = -1; b <= 1; ++b) {
                    const int u = int(std::nearbyint(x + t * f.alongX[i] + b * f.acrossX[i]));
                    const int v = int(std::nearbyint(y + t * f.alongY[i] + b * f.acrossY[i]));
                    if (u < 0 || v < 0 || u >= win.w || v >= win.h || !present(u, v)) continue;
                    const double weight = (s.radius + 1 - std::abs(t)) *
                                          std::exp(-b * b / bandDenominator) * weightAt(u, v);
                    const size_t q = win.Index(u, v);
                    auto it = std::find_if(targets.begin(), targets.end(),
                                           [&](const auto &e) { return e.first == q; });
                    if (it == targets.end())
                        targets.push_back({q, weight});
                    else
                        it->second += weight;
                }
            for (const auto &e : targets) total += e.second;
            if (!(total > 0)) continue;
            for (const auto &e : targets)
                for (int c = 0; c < ch; ++c)
                    add[size_t(c) * n + e.first] += removed[size_t(c)] * e.second / total;
            ++stats.givers;
            stats.moved += Luminance(removed);
        }
    stats.dropped += AddCapped(add, inputLum, f, win, output);
}

}  // namespace

NforLineStats NforSpreadLine(const Image &color, const Image &clamped, const Image &albedo,
                             const Image *alpha, const NforLineSettings &s, Image *output) {
    NforLineStats stats;
    if (!(s.lightAlbedo > 0)) return stats;
    for (const Window &win : FindWindows(albedo, s))
        SpreadWindow(color, clamped, albedo, alpha, s, win, output, &stats);
    return stats;
}

}  // namespace mcd
