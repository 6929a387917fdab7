/* Sierpinski tetrahedron, KIFS form: reflect towards (1,1,1), scale about it. */
real sierpinski(real3 p, int iterations, real scale, real* trap) {
    real3 z = p;
    real s = R(1.0);
    real t = R(1.0);
    real shift = scale - R(1.0);
    for (int i = 0; i < iterations; i++) {
        if (z.x + z.y < R(0.0)) z = (real3)(-z.y, -z.x, z.z);
        if (z.x + z.z < R(0.0)) z = (real3)(-z.z, z.y, -z.x);
        if (z.y + z.z < R(0.0)) z = (real3)(z.x, -z.z, -z.y);
        t = fmin(t, length(z) * R(0.5773502691896258));
        z = z * scale - (real3)(shift);
        s = s * scale;
    }
    *trap = t;
    return sd_tetrahedron(z) / s;
}
