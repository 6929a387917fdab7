/* Rotates p by angle around the unit axis k (Rodrigues' formula). */
real3 rotate_axis(real3 p, real3 k, real angle) {
    real c = cos(angle);
    real s = sin(angle);
    return p * c + cross(k, p) * s + k * (dot(k, p) * (R(1.0) - c));
}
