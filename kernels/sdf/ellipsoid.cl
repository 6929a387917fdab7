/* Quilez's bound k0 (k0 - 1) / k1, with k0 = |p / r| and k1 = |p / r^2|,
   computed as (k0 - 1) / |u / r| with u = (p / r) / k0, so no square of
   p / r or p / r^2 is formed (cpu: sdf::ellipsoid). */
real sd_ellipsoid(real3 p, real3 r) {
    real3 q = p / r;
    real k0 = safe_length(q);
    if (k0 < R(1.0)) {
        return (k0 - R(1.0)) * fmin(fmin(r.x, r.y), r.z);
    }
    real k1 = safe_length(q / k0 / r);
    return (k0 - R(1.0)) / fmax(k1, REAL_TINY);
}
