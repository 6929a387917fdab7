real sd_box(real3 p, real3 b) {
    real3 q = fabs(p) - b;
    return length(fmax(q, (real3)(R(0.0)))) + fmin(fmax(fmax(q.x, q.y), q.z), R(0.0));
}
