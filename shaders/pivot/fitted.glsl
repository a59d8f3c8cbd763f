// A filtered value never bitwise its input: the host's passes after the filter tell the
// values it kept from those it filtered by equality (host/common/kept_edges.cpp, the local
// means' restore), and a fit that rounds onto its input would flip that between this kernel
// and the CPU twin, which rounds once in double. Such a value moves one step away from zero
// (0 to the smallest normal float, which no device flushes); a value not finite is left.
float FittedValue(float fitted, float inputValue) {
    if (floatBitsToUint(fitted) != floatBitsToUint(inputValue) || isinf(fitted) ||
        isnan(fitted))
        return fitted;
    if (fitted == 0.0) return uintBitsToFloat(0x00800000u);
    uint bits = floatBitsToUint(fitted);
    // The largest finite magnitude steps toward zero instead.
    return uintBitsToFloat((bits & 0x7fffffffu) == 0x7f7fffffu ? bits - 1u : bits + 1u);
}
