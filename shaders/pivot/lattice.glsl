// Eq. 13's lattice (cpu_reference/pivot_filter.h): the step of a centre of radius
// `radius`, the largest power of two <= radius / 2, at most PIVOT_LATTICE_MAX_STEP. A
// centre takes part in the gather only when x0 and y0 are multiples of its step.
int latticeStep(float radius) {
    int step = 1;
    while (step < PIVOT_LATTICE_MAX_STEP && float(2 * step) <= radius / 2.0) step *= 2;
    return step;
}

bool onLattice(int x0, int y0, float radius) {
    int step = latticeStep(radius);
    return x0 % step == 0 && y0 % step == 0;
}
