/* Mandelbulb of any real power, with acos/atan2/sin/cos. */
real mandelbulb(real3 p, real power, int iterations, real escape, real ball, real* trap) {
    /* The ball of radius `ball` = 2^(1 / (power - 1)) holds the set (proof: cpu::sdf::mandelbulb_radius);
       beyond 1.5 times its radius (MANDELBULB_FAR_FIELD), its distance alone. */
    real r0 = length(p);
    real outer = r0 - ball;
    if (r0 > R(1.5) * ball) {
        *trap = R(1.0);
        return outer;
    }
    real3 z = p;
    real dr = R(1.0);
    real t = R(1.0);
    for (int i = 0; i < iterations; i++) {
        real r = length(z);
        if (r > escape) {
            break;
        }
        t = fmin(t, r);
        real r_pow = pow(r, power - R(1.0));
        dr = fmin(power * r_pow * dr + R(1.0), DERIVATIVE_CAP);
        real zr = r_pow * r;
        real theta = acos(fmin(fmax(z.z / fmax(r, REAL_TINY), R(-1.0)), R(1.0))) * power;
        real phi = atan2(z.y, z.x) * power;
        real st = sin(theta);
        z = (real3)(st * cos(phi), st * sin(phi), cos(theta)) * zr + p;
    }
    real r = length(z);
    *trap = t;
    return fmax(R(0.5) * log(fmax(r, REAL_TINY)) * r / dr, outer);
}
