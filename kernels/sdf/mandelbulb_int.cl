/* Mandelbulb of integer power n, trig-free (see angle_power). */
real mandelbulb_int(real3 p, int n, int iterations, real bailout, real* trap) {
    /* The ball of radius `ball` holds the set (proof: cpu::sdf::mandelbulb_radius);
       beyond 1.5 times its radius (MANDELBULB_FAR_FIELD), its distance alone. */
    real ball = pow(R(2.0), R(1.0) / (real)(n - 1));
    real r0 = length(p);
    real outer = r0 - ball;
    if (r0 > R(1.5) * ball) {
        *trap = R(1.0);
        return outer;
    }
    real3 z = p;
    real dr = R(1.0);
    real t = R(1.0);
    /* Escape before r^power passes MAGNITUDE_CAP (large powers and bailouts). */
    real escape = fmin(bailout, pow(MAGNITUDE_CAP, R(1.0) / (real)n));
    for (int i = 0; i < iterations; i++) {
        real r = length(z);
        if (r > escape) {
            break;
        }
        t = fmin(t, r);
        real r_pow = pown(r, n - 1);
        dr = fmin((real)n * r_pow * dr + R(1.0), DERIVATIVE_CAP);
        real zr = r_pow * r;
        real rho = hypot(z.x, z.y);
        real inv_r = R(1.0) / fmax(r, REAL_TINY);
        real2 th = angle_power(z.z * inv_r, rho * inv_r, n);
        real2 ph = rho > REAL_TINY ? angle_power(z.x / rho, z.y / rho, n) : (real2)(R(1.0), R(0.0));
        z = (real3)(th.y * ph.x, th.y * ph.y, th.x) * zr + p;
    }
    real r = length(z);
    *trap = t;
    return fmax(R(0.5) * log(fmax(r, REAL_TINY)) * r / dr, outer);
}
