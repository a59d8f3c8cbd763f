// A filtered value never its input but for 0 (host/common/kept_edges.h, FilteredValue): the
// host's passes after the filter tell the values it kept by equality, and a fit that rounds
// onto its input would count as kept here or in the CPU twin (double, rounded once) alone.
// Where it equals a nonzero input and is finite, the next float away from zero (the largest
// finite magnitude steps toward zero); a zero on an input of zero is the input, kept. Tested
// on the bits: a device may assume floats finite or flush denormals in a comparison.
float FilteredValue(float fitted, float inputValue) {
    uint bits = floatBitsToUint(fitted), inputBits = floatBitsToUint(inputValue);
    if (((bits | inputBits) & 0x7fffffffu) == 0u) return inputValue;
    if (bits != inputBits || (bits & 0x7f800000u) == 0x7f800000u) return fitted;
    return uintBitsToFloat((bits & 0x7fffffffu) == 0x7f7fffffu ? bits - 1u : bits + 1u);
}
