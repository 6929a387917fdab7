real sd_torus(real3 p, real major, real minor) {
    real qx = hypot(p.x, p.z) - major;
    return hypot(qx, p.y) - minor;
}
