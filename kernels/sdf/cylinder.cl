real sd_cylinder(real3 p, real r, real h) {
    real dx = hypot(p.x, p.z) - r;
    real dy = fabs(p.y) - h;
    return fmin(fmax(dx, dy), R(0.0)) + hypot(fmax(dx, R(0.0)), fmax(dy, R(0.0)));
}
