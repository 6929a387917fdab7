real sd_capsule(real3 p, real3 a, real3 b, real r) {
    real3 pa = p - a;
    real3 ba = b - a;
    real h = fmin(fmax(dot(pa, ba) / fmax(dot(ba, ba), REAL_TINY), R(0.0)), R(1.0));
    return length(pa - ba * h) - r;
}
