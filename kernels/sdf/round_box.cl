real sd_round_box(real3 p, real3 b, real r) {
    real3 q = fabs(p) - b + r;
    return length(fmax(q, (real3)(R(0.0)))) + fmin(fmax(fmax(q.x, q.y), q.z), R(0.0)) - r;
}
