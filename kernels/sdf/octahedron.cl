real sd_octahedron(real3 p, real s) {
    p = fabs(p);
    real m = p.x + p.y + p.z - s;
    real3 q;
    if (R(3.0) * p.x < m) {
        q = p;
    } else if (R(3.0) * p.y < m) {
        q = (real3)(p.y, p.z, p.x);
    } else if (R(3.0) * p.z < m) {
        q = (real3)(p.z, p.x, p.y);
    } else {
        return m * R(0.5773502691896258);
    }
    real k = fmin(fmax(R(0.5) * (q.z - q.y + s), R(0.0)), s);
    return length((real3)(q.x, q.y - s + k, q.z - k));
}
