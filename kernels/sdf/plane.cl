real sd_plane(real3 p, real3 n, real offset) {
    n = n / fmax(length(n), REAL_TINY);
    return dot(p, n) + offset;
}
