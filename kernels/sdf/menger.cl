/* Menger sponge, KIFS form: fold, scale about the kept cube, box bound. */
real menger(real3 p, int iterations, real scale, real* trap) {
    real3 z = p;
    real s = R(1.0);
    real t = R(1.0);
    real shift = scale - R(1.0);
    for (int i = 0; i < iterations; i++) {
        z = fabs(z);
        if (z.x < z.y) z = z.yxz;
        if (z.x < z.z) z = z.zyx;
        if (z.y < z.z) z = z.xzy;
        t = fmin(t, length(z) * R(0.5773502691896258));
        z = (real3)(z.x * scale - shift, z.y * scale - shift, z.z * scale);
        if (z.z > R(0.5) * shift) z.z = z.z - shift;
        s = s * scale;
    }
    *trap = t;
    return sd_box(z, (real3)(R(1.0))) / s;
}
