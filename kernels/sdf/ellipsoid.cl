real sd_ellipsoid(real3 p, real3 r) {
    real k0 = length(p / r);
    if (k0 < R(1.0)) {
        return (k0 - R(1.0)) * fmin(fmin(r.x, r.y), r.z);
    }
    real k1 = length(p / (r * r));
    return k0 * (k0 - R(1.0)) / fmax(k1, REAL_TINY);
}
