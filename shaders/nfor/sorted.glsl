// Small sorted windows kept in registers: the loops unrolled, so that the arrays are indexed
// by constants only (an array indexed per invocation is kept in memory, per lane). Needs
// GL_EXT_control_flow_attributes.

// Inserts v into the n values (n < 9) of s sorted ascending after every value not above it,
// as an insertion sort inserts it.
void insertSorted(inout float s[9], int n, float v) {
    bool placed = false;
    [[unroll]] for (int i = 8; i >= 1; --i) {
        if (i <= n && !placed) {
            if (s[i - 1] > v) {
                s[i] = s[i - 1];
            } else {
                s[i] = v;
                placed = true;
            }
        }
    }
    if (!placed) s[0] = v;
}

// s[k] (k < 9), read through constant indices.
float pickSorted(float s[9], int k) {
    float picked = s[0];
    [[unroll]] for (int i = 1; i < 9; ++i) {
        if (k == i) picked = s[i];
    }
    return picked;
}
