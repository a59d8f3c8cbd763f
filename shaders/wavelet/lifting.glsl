// Shared-memory tile and lifting steps for the wavelet kernels. Include after the
// kernel's header. Tile coordinates: local (tx, ty) in [0, WAVELET_TILE_EXT) is position
// (origin.x + tx, origin.y + ty) with origin = group * WAVELET_TILE - WAVELET_HALO; the
// origin is even, so local parity is position parity (even = low-pass, odd = high-pass).

layout(constant_id = 0) const int WAVELET = MCD_WAVELET_CDF97;

const int kExt = WAVELET_TILE_EXT;
const int kLocal = WAVELET_LOCAL_SIZE;
// Positions of one parity that have both neighbours in the tile: 1..kExt-2.
const int kInner = (kExt - 2) / 2;

// CDF 9/7 lifting factorisation (Daubechies and Sweldens) and the scaling that gives the
// filter bank of AWR appendix A (low-pass sums to sqrt 2).
const float kAlpha = -1.586134342059924;
const float kBeta = -0.052980118572961;
const float kGamma = 0.882911075530934;
const float kDelta = 0.443506852043971;
const float kZeta = 1.149604398860241;
const float kSqrt2 = 1.4142135623730951;

shared float tile[kExt * kExt];

// Fold a position into [0, n): whole-sample symmetric for the odd-length banks (parity
// preserving), half-sample symmetric for Haar (its unpaired last sample pairs with itself).
int MirrorAnalysis(int p, int n) {
    if (n == 1) return 0;
    if (WAVELET == MCD_WAVELET_HAAR) {
        int period = 2 * n;
        p = p % period;
        if (p < 0) p += period;
        return p < n ? p : period - 1 - p;
    }
    int period = 2 * (n - 1);
    p = p % period;
    if (p < 0) p += period;
    return p < n ? p : period - p;
}

// Scale of the low (even) and high (odd) outputs after the lifting steps.
float LowScale() {
    return WAVELET == MCD_WAVELET_CDF97 ? kZeta : kSqrt2;
}
float HighScale() {
    if (WAVELET == MCD_WAVELET_CDF97) return 1.0 / kZeta;
    // The paper's LeGall high-pass has the opposite sign to its 9/7 one.
    if (WAVELET == MCD_WAVELET_LEGALL53) return -1.0 / kSqrt2;
    return 1.0 / kSqrt2;
}

// Band index of a position along an axis of length n: low coefficients first, then high.
int BandIndex(int p, int n) {
    if (n == 1) return p;
    return (p & 1) == 0 ? (p >> 1) : ((n + 1) >> 1) + (p >> 1);
}

// x[p] += left * x[p-1] + right * x[p+1] for positions p of `parity` along rows
// [row0, row1) of the tile.
void StepX(int parity, float left, float right, int row0, int row1) {
    int start = parity == 1 ? 1 : 2;
    int count = (row1 - row0) * kInner;
    for (int i = int(gl_LocalInvocationIndex); i < count; i += kLocal) {
        int r = row0 + i / kInner;
        int at = r * kExt + start + 2 * (i % kInner);
        tile[at] += left * tile[at - 1] + right * tile[at + 1];
    }
    barrier();
}

// The same along columns [col0, col1) of the tile.
void StepY(int parity, float left, float right, int col0, int col1) {
    int start = parity == 1 ? 1 : 2;
    int cols = col1 - col0;
    int count = cols * kInner;
    for (int i = int(gl_LocalInvocationIndex); i < count; i += kLocal) {
        int at = (start + 2 * (i / cols)) * kExt + col0 + i % cols;
        tile[at] += left * tile[at - kExt] + right * tile[at + kExt];
    }
    barrier();
}

void ForwardX(int row0, int row1) {
    if (WAVELET == MCD_WAVELET_CDF97) {
        StepX(1, kAlpha, kAlpha, row0, row1);
        StepX(0, kBeta, kBeta, row0, row1);
        StepX(1, kGamma, kGamma, row0, row1);
        StepX(0, kDelta, kDelta, row0, row1);
    } else if (WAVELET == MCD_WAVELET_LEGALL53) {
        StepX(1, -0.5, -0.5, row0, row1);
        StepX(0, 0.25, 0.25, row0, row1);
    } else {
        StepX(1, -1.0, 0.0, row0, row1);
        StepX(0, 0.0, 0.5, row0, row1);
    }
}

void ForwardY(int col0, int col1) {
    if (WAVELET == MCD_WAVELET_CDF97) {
        StepY(1, kAlpha, kAlpha, col0, col1);
        StepY(0, kBeta, kBeta, col0, col1);
        StepY(1, kGamma, kGamma, col0, col1);
        StepY(0, kDelta, kDelta, col0, col1);
    } else if (WAVELET == MCD_WAVELET_LEGALL53) {
        StepY(1, -0.5, -0.5, col0, col1);
        StepY(0, 0.25, 0.25, col0, col1);
    } else {
        StepY(1, -1.0, 0.0, col0, col1);
        StepY(0, 0.0, 0.5, col0, col1);
    }
}

// Undo the steps in reverse order.
void InverseX(int row0, int row1) {
    if (WAVELET == MCD_WAVELET_CDF97) {
        StepX(0, -kDelta, -kDelta, row0, row1);
        StepX(1, -kGamma, -kGamma, row0, row1);
        StepX(0, -kBeta, -kBeta, row0, row1);
        StepX(1, -kAlpha, -kAlpha, row0, row1);
    } else if (WAVELET == MCD_WAVELET_LEGALL53) {
        StepX(0, -0.25, -0.25, row0, row1);
        StepX(1, 0.5, 0.5, row0, row1);
    } else {
        StepX(0, 0.0, -0.5, row0, row1);
        StepX(1, 1.0, 0.0, row0, row1);
    }
}

void InverseY(int col0, int col1) {
    if (WAVELET == MCD_WAVELET_CDF97) {
        StepY(0, -kDelta, -kDelta, col0, col1);
        StepY(1, -kGamma, -kGamma, col0, col1);
        StepY(0, -kBeta, -kBeta, col0, col1);
        StepY(1, -kAlpha, -kAlpha, col0, col1);
    } else if (WAVELET == MCD_WAVELET_LEGALL53) {
        StepY(0, -0.25, -0.25, col0, col1);
        StepY(1, 0.5, 0.5, col0, col1);
    } else {
        StepY(0, 0.0, -0.5, col0, col1);
        StepY(1, 1.0, 0.0, col0, col1);
    }
}
