/* (cos, sin) of n times the angle whose cosine and sine are (c, s):
   binary exponentiation of c + i s, the trig-free integer power. */
real2 angle_power(real c, real s, int n) {
    real rc = R(1.0), rs = R(0.0);
    real bc = c, bs = s;
    for (int e = n; e > 0; e >>= 1) {
        if (e & 1) {
            real t = rc * bc - rs * bs;
            rs = rc * bs + rs * bc;
            rc = t;
        }
        real u = bc * bc - bs * bs;
        bs = R(2.0) * bc * bs;
        bc = u;
    }
    return (real2)(rc, rs);
}
