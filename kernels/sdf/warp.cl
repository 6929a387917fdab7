/* Distance bounds for warped children (twist, bend): with the warp's local
   stretch L(rho), d / L(rho + |d| / L(rho)) never overestimates. The
   twist's root is a hypot, so a large rate never makes L infinite. */
real twist_stretch(real k, real rho) {
    real a = R(0.5) * fabs(k) * rho;
    return a + hypot(R(1.0), a);
}

real bend_stretch(real k, real rho) {
    return R(1.0) + fabs(k) * rho;
}

real twist_bound(real d, real k, real rho) {
    real reach = fabs(d) / twist_stretch(k, rho);
    return d / twist_stretch(k, rho + reach);
}

real bend_bound(real d, real k, real rho) {
    real reach = fabs(d) / bend_stretch(k, rho);
    return d / bend_stretch(k, rho + reach);
}
