/* n is scaled by its largest component before it is normalised, so no
   square of a tiny or huge component is formed (cpu: sdf::plane). */
real sd_plane(real3 p, real3 n, real offset) {
    real m = fmax(fmax(fabs(n.x), fabs(n.y)), fabs(n.z));
    if (m > R(0.0)) {
        n = n / m;
        n = n / length(n);
    }
    return dot(p, n) + offset;
}
