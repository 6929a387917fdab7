//! Structure specialisation for the Mandelbulb: for a baked integer power
//! `n`, a helper `mandelbulb_pN` with the power unrolled into straight-line
//! multiplications (no loop over the bits of `n`, no trigonometry).
//!
//! The unrolled code performs exactly the multiplications of the CPU
//! reference's binary exponentiation (`cpu::sdf::pow_int` and the angle
//! power inside `cpu::sdf::mandelbulb`), minus the multiplications by the
//! initial one, which are exact; so the twins still agree bit for bit up to
//! the built-in functions.

use std::fmt::Write as _;

/// Statements computing `{out} = {x}^n` into fresh variables prefixed
/// `prefix`, by binary exponentiation.
fn pow_lines(out: &str, x: &str, n: u32, prefix: &str, code: &mut String) {
    let mut base = x.to_string();
    let mut result: Option<String> = None;
    let mut e = n;
    let mut k = 0;
    while e > 0 {
        if e & 1 == 1 {
            result = Some(match result {
                None => base.clone(),
                Some(r) => {
                    let v = format!("{prefix}r{k}");
                    writeln!(code, "        real {v} = {r} * {base};").expect("String");
                    v
                }
            });
        }
        e >>= 1;
        if e > 0 {
            let v = format!("{prefix}b{k}");
            writeln!(code, "        real {v} = {base} * {base};").expect("String");
            base = v;
        }
        k += 1;
    }
    let r = result.unwrap_or_else(|| "R(1.0)".into());
    writeln!(code, "        real {out} = {r};").expect("String");
}

/// Statements computing `({out}c, {out}s)`, the cosine and sine of `n`
/// times the angle whose cosine and sine are `c` and `s`.
fn angle_lines(out: &str, c: &str, s: &str, n: u32, code: &mut String) {
    let (mut bc, mut bs) = (c.to_string(), s.to_string());
    let mut result: Option<(String, String)> = None;
    let mut e = n;
    let mut k = 0;
    while e > 0 {
        if e & 1 == 1 {
            result = Some(match result {
                None => (bc.clone(), bs.clone()),
                Some((rc, rs)) => {
                    let (vc, vs) = (format!("{out}rc{k}"), format!("{out}rs{k}"));
                    writeln!(code, "        real {vc} = {rc} * {bc} - {rs} * {bs};")
                        .expect("String");
                    writeln!(code, "        real {vs} = {rc} * {bs} + {rs} * {bc};")
                        .expect("String");
                    (vc, vs)
                }
            });
        }
        e >>= 1;
        if e > 0 {
            let (vc, vs) = (format!("{out}bc{k}"), format!("{out}bs{k}"));
            writeln!(code, "        real {vc} = {bc} * {bc} - {bs} * {bs};").expect("String");
            writeln!(code, "        real {vs} = R(2.0) * {bc} * {bs};").expect("String");
            (bc, bs) = (vc, vs);
        }
        k += 1;
    }
    let (rc, rs) = result.unwrap_or_else(|| ("R(1.0)".into(), "R(0.0)".into()));
    writeln!(code, "        real {out}c = {rc};").expect("String");
    writeln!(code, "        real {out}s = {rs};").expect("String");
}

/// The name of the specialised helper for power `n`.
pub(crate) fn helper_name(n: u32) -> String {
    format!("mandelbulb_p{n}")
}

/// The OpenCL source of the Mandelbulb helper specialised to power `n`.
pub(crate) fn mandelbulb_helper(n: u32) -> String {
    let mut code = String::new();
    let name = helper_name(n);
    writeln!(
        code,
        "/* Mandelbulb of power {n}, unrolled: no loop over the power, no trigonometry. */"
    )
    .expect("String");
    writeln!(
        code,
        "real {name}(real3 p, int iterations, real escape, real ball, real* trap) {{"
    )
    .expect("String");
    // The far field, as in the generic helper: the ball of radius `ball`,
    // 2^(1 / (n - 1)), holds the set (proof: math::mandelbulb_radius).
    code.push_str(
        "    real r0 = length(p);\n    real outer = r0 - ball;\n    \
         if (r0 > R(1.5) * ball) {\n        *trap = R(1.0);\n        return outer;\n    }\n",
    );
    code.push_str(
        "    real3 z = p;\n    real dr = R(1.0);\n    real t = R(1.0);\n    \
         for (int i = 0; i < iterations; i++) {\n        real r = length(z);\n        \
         if (r > escape) {\n            break;\n        }\n        t = fmin(t, r);\n",
    );
    pow_lines("r_pow", "r", n - 1, "q", &mut code);
    writeln!(
        code,
        "        dr = fmin(R({n}.0) * r_pow * dr + R(1.0), DERIVATIVE_CAP);"
    )
    .expect("String");
    code.push_str(
        "        real zr = r_pow * r;\n        real rho = hypot(z.x, z.y);\n        \
         real inv_r = R(1.0) / fmax(r, REAL_TINY);\n        \
         real ct = z.z * inv_r;\n        real st = rho * inv_r;\n        \
         real cp = R(1.0);\n        real sp = R(0.0);\n        \
         if (rho > REAL_TINY) {\n            cp = z.x / rho;\n            sp = z.y / rho;\n        }\n",
    );
    angle_lines("th", "ct", "st", n, &mut code);
    angle_lines("ph", "cp", "sp", n, &mut code);
    code.push_str(
        "        z = (real3)(ths * phc, ths * phs, thc) * zr + p;\n    }\n    \
         real r = length(z);\n    *trap = t;\n    \
         return fmax(R(0.5) * log(fmax(r, REAL_TINY)) * r / dr, outer);\n}\n",
    );
    code
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_eight_is_three_squarings() {
        let src = mandelbulb_helper(8);
        assert!(src.contains("real mandelbulb_p8("));
        // 8 = 2^3: three doublings of each angle, no other products.
        assert_eq!(src.matches("R(2.0) * thbc").count(), 2);
        assert!(!src.contains("thrc"), "{src}");
        // r^7 = r * r^2 * r^4: two squarings and two products.
        assert!(src.contains("real qb0 = r * r;"));
        assert!(src.contains("real r_pow = qr2;"), "{src}");
        assert!(!src.contains("for (int e"));
    }

    #[test]
    fn power_two_has_no_product_for_r() {
        let src = mandelbulb_helper(2);
        assert!(src.contains("real r_pow = r;"));
    }
}
