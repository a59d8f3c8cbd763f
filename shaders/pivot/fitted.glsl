// A filtered value never its input (host/common/kept_edges.h, FilteredValue): the host's
// passes after the filter tell the values it kept by equality, and a fit that rounds onto its
// input would count as kept here or in the CPU twin (double, rounded once) alone. Where it
// equals the input (as floats: +0 and -0 too) and is finite, the next float away from zero (0
// becomes the smallest normal float, which no device flushes; the largest finite magnitude
// steps toward zero). Tested on the bits: a device may assume floats finite.
float FilteredValue(float fitted, float inputValue) {
    uint bits = floatBitsToUint(fitted), inputBits = floatBitsToUint(inputValue);
    // Equal as floats, on the bits (a device may flush denormals in a comparison).
    bool equal = bits == inputBits || ((bits | inputBits) & 0x7fffffffu) == 0u;
    if (!equal || (bits & 0x7f800000u) == 0x7f800000u) return fitted;
    if ((bits & 0x7fffffffu) == 0u) return uintBitsToFloat(0x00800000u);
    return uintBitsToFloat((bits & 0x7fffffffu) == 0x7f7fffffu ? bits - 1u : bits + 1u);
}
