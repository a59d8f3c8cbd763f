// The stored offsets of a window of half-size R: index j is raster position
// (side^2 + 1) / 2 + j of the (2R + 1)^2 window, the positions after its centre.
ivec2 storedOffset(int radius, int j) {
    int side = 2 * radius + 1;
    int index = (side * side + 1) / 2 + j;
    return ivec2(index % side - radius, index / side - radius);
}
