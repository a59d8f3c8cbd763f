// Boundary folding shared by the wavelet kernels. Include after declaring the basis
// constant WAVELET (MCD_WAVELET_*).
#ifndef MCD_SHADERS_WAVELET_FOLD_GLSL
#define MCD_SHADERS_WAVELET_FOLD_GLSL

// Fold a position into [0, n): whole-sample symmetric for the odd-length banks (parity
// preserving), half-sample symmetric for Haar (its unpaired last sample pairs with itself).
// Reflect until inside rather than take a modulo: lavapipe runs both sides of a branch
// under a mask, and vector integer division is scalarised, so a `%` here would cost
// every load; the loop runs zero times inside the region and once in the apron.
int MirrorAnalysis(int p, int n) {
    if (n == 1) return 0;
    while (p < 0 || p >= n) {
        if (WAVELET == MCD_WAVELET_HAAR)
            p = p < 0 ? -1 - p : 2 * n - 1 - p;
        else
            p = p < 0 ? -p : 2 * (n - 1) - p;
    }
    return p;
}

#endif
