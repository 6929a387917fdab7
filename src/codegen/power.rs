//! Structure specialisation for the Mandelbulb: for a baked integer power
//! `n`, a helper `mandelbulb_pN` printed from the one Mandelbulb formula
//! ([`cpu::sdf::mandelbulb_estimate`](crate::cpu::sdf::mandelbulb_estimate))
//! traced with the power fixed: its binary exponentiation and angle powers
//! unroll into straight-line multiplications (no loop over the bits of
//! `n`, no trigonometry).

use crate::expr::Unprintable;

/// The helper's name for power `n`.
pub(crate) fn helper_name(n: u32) -> String {
    format!("mandelbulb_p{n}")
}

/// The helper for power `n`.
pub(crate) fn mandelbulb_helper(n: u32) -> Result<String, Unprintable> {
    super::formulas::mandelbulb_power(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_eight_needs_no_trigonometry_and_three_squarings() {
        let src = mandelbulb_helper(8).unwrap();
        assert!(src.contains("real2 mandelbulb_p8("), "{src}");
        for f in ["sin(", "cos(", "acos(", "atan2(", "pow("] {
            assert!(!src.contains(f), "{f} in {src}");
        }
        // r^7 = r * r^2 * r^4: r is squared, and squared again.
        assert!(src.contains("R(2.0) *"), "{src}");
    }

    #[test]
    fn a_real_power_uses_the_trigonometric_form() {
        let src = super::super::formulas::mandelbulb().unwrap();
        for f in ["acos(", "atan2(", "pow("] {
            assert!(src.contains(f), "{f} missing from {src}");
        }
    }
}
