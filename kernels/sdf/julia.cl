/* The radius of the ball that holds the quaternion Julia set of c (cpu::sdf::julia_radius). */
real julia_radius(real4 c) {
    return R(0.5) + sqrt(R(0.5) * R(0.5) + sqrt(dot(c, c)));
}

/* Whether the critical orbit 0, c, c^2 + c, ... (as the complex orbit of
   c.x + i |c.yzw|) leaves |w|^2 <= radius2 within `steps` steps. */
int julia_critical_leaves(real4 c, int steps, real radius2) {
    real cy = sqrt(c.y * c.y + c.z * c.z + c.w * c.w);
    real x = R(0.0);
    real y = R(0.0);
    for (int i = 0; i < steps; i++) {
        real two_x = R(2.0) * x;
        x = x * x - y * y + c.x;
        y = two_x * y + cy;
        if (x * x + y * y > radius2) {
            return 1;
        }
    }
    return 0;
}

/* A proven lower bound of the distance to the points whose orbits stay
   within `edge`, from the first steps + 1 points of the orbit; 0 where none
   proves escape (proof: cpu::sdf::julia_bound). */
real julia_bound(real3 p, real4 c, real w, int steps, real edge, real guess) {
    real far2 = R(1e18) * R(1e18);
    real4 z = (real4)(p, w);
    real mz2 = dot(z, z);
    real a = R(1.0);
    real b = R(0.0);
    real d = R(1.0);
    real best = R(0.0);
    for (int k = 0; k <= steps; k++) {
        if (mz2 > far2) {
            break;
        }
        real r = sqrt(mz2);
        real t = r - edge;
        if (t > R(0.0)) {
            best = fmax(best, t / (a + b * t));
        }
        if (k == steps) {
            break;
        }
        d = fmin(d * R(2.0) * r, DERIVATIVE_CAP);
        real tau = fmin(guess * d, DERIVATIVE_CAP);
        real s = fmax(sqrt(mz2 + tau), REAL_TINY);
        real half_inv = R(0.5) / s;
        b = fmin(a * half_inv + b, DERIVATIVE_CAP);
        a = fmin(a * (r + s - tau * half_inv), DERIVATIVE_CAP);
        real two_x = R(2.0) * z.x;
        z = (real4)(z.x * z.x - z.y * z.y - z.z * z.z - z.w * z.w, two_x * z.y, two_x * z.z, two_x * z.w) + c;
        mz2 = dot(z, z);
    }
    return best;
}

/* Quaternion Julia z -> z^2 + c at the point (p, w), real part first: 0.9
   times the ball's distance far away (beyond 1.5 radii, JULIA_FAR_FIELD);
   nearer the escape-time estimate where trusted (bailout >= 2.5 radii,
   critical orbit within 0.9 for n + 2 steps), else no more than
   julia_bound (cpu::sdf::julia). */
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
    int n = 0;
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
        n++;
        if (mz2 > bailout2) {
            break;
        }
    }
    *trap = fmin(sqrt(t), R(1.0));
    real ratio = sqrt(mz2 / fmax(md2, REAL_TINY));
    real d = R(0.25) * log(fmax(mz2, REAL_TINY)) * ratio;
    if (bailout < R(2.5) * radius || julia_critical_leaves(c, n + 2, R(0.9) * R(0.9))) {
        d = fmin(d, julia_bound(p, c, w, n + 2, edge, ratio));
    }
    return d;
}
