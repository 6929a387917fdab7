real sd_sphere(real3 p, real r) {
    return length(p) - r;
}
