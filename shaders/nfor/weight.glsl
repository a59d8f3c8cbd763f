// The weight of q in p's window, shared by regress and gather so that both compute the
// same bits. Needs w, h, the mask, features and distance buffers, `features` planes.

float distanceOf(int px, int py, int qx, int qy) {
    int r = push.radius, ox = qx - px, oy = qy - py;
    int side = 2 * r + 1, centre = (side * side - 1) / 2;
    int index = (oy + r) * side + ox + r;
    if (index > centre) return distance[((index - centre - 1) * h + py) * w + px];
    int mirrored = (r - oy) * side + r - ox;
    return distance[((mirrored - centre - 1) * h + qy) * w + qx];
}

float weightOf(int px, int py, int qx, int qy) {
    if (qx < 0 || qy < 0 || qx >= w || qy >= h) return 0.0;
    if (mask[qy * w + qx] == 0.0 || mask[py * w + px] == 0.0) return 0.0;
    if (qx == px && qy == py) return 1.0;
    float e = max(0.0, distanceOf(px, py, qx, qy)) * push.invBandwidth2;
    for (int j = 0; j < featureCount; ++j) {
        float d = push.featureWeight[j] *
                  (features[(j * h + qy) * w + qx] - features[(j * h + py) * w + px]);
        e += d * d;
    }
    return e > NFOR_EXP_CUT ? 0.0 : exp(-e);
}

// The regression's columns of q in p's window, into col.
float col[NFOR_MAX_FEATURES + 3];
void columnsOf(int px, int py, int qx, int qy) {
    col[0] = 1.0;
    col[1] = float(qx - px) / float(push.radius);
    col[2] = float(qy - py) / float(push.radius);
    for (int j = 0; j < featureCount; ++j)
        col[3 + j] = features[(j * h + qy) * w + qx] - features[(j * h + py) * w + px];
}
