/* The radius of the ball that holds the quaternion Julia set of c (cpu::sdf::julia_radius). */
real julia_radius(real4 c) {
    return R(0.5) + sqrt(R(0.5) * R(0.5) + sqrt(dot(c, c)));
}

/* Quaternion Julia z -> z^2 + c at the point (p, w), real part first;
   beyond 1.5 radii of its ball (JULIA_FAR_FIELD), 0.9 times the ball's
   distance. */
real julia(real3 p, real4 c, real w, int iterations, real bailout, real* trap) {
    real radius = julia_radius(c);
    real edge = fmin(radius, bailout);
    real4 z = (real4)(p, w);
    real mz2 = dot(z, z);
    real r0 = sqrt(mz2);
    if (r0 > R(1.5) * edge) {
        *trap = R(1.0);
        return R(0.9) * (r0 - edge);
    }
    real md2 = R(1.0);
    real t = mz2;
    real bailout2 = bailout * bailout;
    for (int i = 0; i < iterations; i++) {
        real next = md2 * R(4.0) * mz2;
        if (next > DERIVATIVE_CAP) {
            break;
        }
        md2 = next;
        real two_x = R(2.0) * z.x;
        z = (real4)(z.x * z.x - z.y * z.y - z.z * z.z - z.w * z.w, two_x * z.y, two_x * z.z, two_x * z.w) + c;
        mz2 = dot(z, z);
        t = fmin(t, mz2);
        if (mz2 > bailout2) break;
    }
    *trap = fmin(sqrt(t), R(1.0));
    return R(0.25) * log(fmax(mz2, REAL_TINY)) * sqrt(mz2 / fmax(md2, REAL_TINY));
}
