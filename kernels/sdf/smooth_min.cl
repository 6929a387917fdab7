/* Polynomial smooth minimum of radius k: (value, blend weight of the far operand).
   Exactly min(a, b) with weight 0 when k = 0. */
real2 smooth_min(real a, real b, real k) {
    if (k <= R(0.0)) {
        return (real2)(fmin(a, b), R(0.0));
    }
    real h = fmax(k - fabs(a - b), R(0.0)) / k;
    real m = h * h * R(0.5);
    return (real2)(fmin(a, b) - m * k * R(0.5), m);
}
