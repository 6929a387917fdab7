real sd_tetrahedron(real3 z) {
    real a = fmax(-z.x - z.y - z.z, z.x + z.y - z.z);
    real b = fmax(-z.x + z.y + z.z, z.x - z.y + z.z);
    return (fmax(a, b) - R(1.0)) * R(0.5773502691896258);
}
