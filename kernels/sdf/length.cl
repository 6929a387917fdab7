/* Euclidean length without overflow or underflow in the squares: v is
   divided by its largest component first (cpu: V3::safe_length). */
real safe_length(real3 v) {
    real m = fmax(fmax(fabs(v.x), fabs(v.y)), fabs(v.z));
    return m > R(0.0) && isfinite(m) ? m * length(v / m) : length(v);
}
