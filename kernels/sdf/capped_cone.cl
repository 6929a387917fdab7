real sd_capped_cone(real3 p, real h, real r1, real r2) {
    real qx = hypot(p.x, p.z);
    real qy = p.y;
    real k1x = r2, k1y = h;
    real k2x = r2 - r1, k2y = R(2.0) * h;
    real cap_r = qy < R(0.0) ? r1 : r2;
    real cax = qx - fmin(qx, cap_r);
    real cay = fabs(qy) - h;
    real k2_len2 = fmax(k2x * k2x + k2y * k2y, REAL_TINY);
    real t = fmin(fmax(((k1x - qx) * k2x + (k1y - qy) * k2y) / k2_len2, R(0.0)), R(1.0));
    real cbx = qx - k1x + k2x * t;
    real cby = qy - k1y + k2y * t;
    real s = (cbx < R(0.0) && cay < R(0.0)) ? R(-1.0) : R(1.0);
    return s * sqrt(fmin(cax * cax + cay * cay, cbx * cbx + cby * cby));
}
