// The shading-edge test of the fits and the gather (cpu_reference/pivot_filter.h): a pixel
// and a centre lie across a shading edge the pivot does not show (a sun patch on a floor)
// when their levels (the median of z over the valid 3x3 neighbours, zsn.w) differ by over
// PIVOT_EDGE_CONTRAST times the smaller and by over `sigmas` standard deviations of the two
// levels' noise (read as each window's noise, the mean of its variances s, over its 9
// pixels). sigmas <= 0: no test.
bool acrossEdge(float zq, float sq, float zc, float sc, float sigmas) {
    if (sigmas <= 0.0) return false;
    float gap = abs(zq - zc);
    return gap > PIVOT_EDGE_CONTRAST * min(abs(zq), abs(zc)) &&
           3.0 * gap > sigmas * sqrt(sq + sc);
}
