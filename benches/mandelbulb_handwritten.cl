/* A hand-written distance estimator for the gallery's Mandelbulb (power 8,
   10 iterations, bailout 2, rotated -90 degrees about x, one colour), as an
   experienced shader author would write it: the rotation as a swizzle, the
   power-8 map by three angle doublings, no trigonometry, and the same
   bounding ball (radius 2^(1/7)) as the library's estimator. It replaces
   the generated scene functions in the render benchmark, which compares
   the two programs' speed with everything else identical. */

real bulb(real3 p, real* trap) {
    /* rotate(-pi/2 about x): q = (x, -z, y) */
    real3 c = (real3)(p.x, -p.z, p.y);
    const real ball = R(1.1040895136738123);
    real r0 = length(c);
    if (r0 > R(1.5) * ball) {
        *trap = R(1.0);
        return r0 - ball;
    }
    real3 z = c;
    real dr = R(1.0);
    real t = R(1.0);
    for (int i = 0; i < 10; i++) {
        real r = length(z);
        if (r > R(2.0)) {
            break;
        }
        t = fmin(t, r);
        real r2 = r * r;
        real r4 = r2 * r2;
        real r7 = r4 * r2 * r;
        dr = R(8.0) * r7 * dr + R(1.0);
        real rho = hypot(z.x, z.y);
        real inv_r = R(1.0) / fmax(r, R(1e-30));
        /* cos and sin of theta and phi, then doubled three times. */
        real ct = z.z * inv_r, st = rho * inv_r;
        real cp = R(1.0), sp = R(0.0);
        if (rho > R(1e-30)) {
            cp = z.x / rho;
            sp = z.y / rho;
        }
        for (int k = 0; k < 3; k++) {
            real a = ct * ct - st * st;
            st = R(2.0) * ct * st;
            ct = a;
            real b = cp * cp - sp * sp;
            sp = R(2.0) * cp * sp;
            cp = b;
        }
        z = (real3)(st * cp, st * sp, ct) * (r7 * r) + c;
    }
    real r = length(z);
    *trap = t;
    return fmax(R(0.5) * log(fmax(r, R(1e-30))) * r / dr, r0 - ball);
}

real DE(real3 p, __global const real* params) {
    real t;
    return bulb(p, &t);
}

real DE_shade(real3 p, __global const real* params, real3* color, real* trap) {
    *color = (real3)(R(0.9), R(0.6), R(0.35));
    return bulb(p, trap);
}
