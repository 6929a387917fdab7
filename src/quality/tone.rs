//! The display transform: exposure, tone mapping and gamma, written once
//! (over [`Num`]) for the kernel's 8-bit image and the host's 16-bit ones.

use super::*;
use crate::expr::Num;
use crate::math::{V3, v3};

/// How linear colours above 1 become displayable ones
/// ([`Effects::tone_map`]). Every curve takes 0 to 0, is monotone, and is
/// applied per channel after [`Effects::exposure`] and before the gamma.
///
/// | curve | `f(x)` | at 1 | reaches 1 |
/// |---|---|---:|---|
/// | `Clip` | `min(x, 1)` | 1 | at 1 |
/// | `Reinhard` | `x / (1 + x)` | 0.5 | never |
/// | `Filmic` | `x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)`, at most 1 | 0.80 | near 7.24 |
///
/// `Filmic` is Krzysztof Narkowicz's fit of the ACES reference rendering
/// transform's tone curve: a toe that deepens the darks a little and a
/// shoulder that rolls highlights off instead of clipping them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum ToneMap {
    /// Values above 1 are clipped to 1 (the default): a scene lit to stay
    /// below 1 shows as lit.
    #[default]
    Clip,
    /// `x / (1 + x)`: nothing clips, but mid-tones darken (1 shows as 0.5).
    Reinhard,
    /// An S-curve after the ACES filmic tone curve.
    Filmic,
}

impl ToneMap {
    /// Every curve, in the order of the table.
    pub const ALL: [ToneMap; 3] = [ToneMap::Clip, ToneMap::Reinhard, ToneMap::Filmic];

    /// The curve's name in scene files and on the command line (`clip`,
    /// `reinhard`, `filmic`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Clip => "clip",
            ToneMap::Reinhard => "reinhard",
            ToneMap::Filmic => "filmic",
        }
    }

    /// The curve named `name` (as [`ToneMap::name`] writes it, any case).
    #[must_use]
    pub fn from_name(name: &str) -> Option<ToneMap> {
        ToneMap::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(name))
    }

    /// The curve at `x` (a linear value at least 0), in `[0, 1]`.
    pub fn apply<N: Num>(self, x: N) -> N {
        let x = x.max(N::zero());
        let y = match self {
            ToneMap::Clip => x,
            ToneMap::Reinhard => x / (x + N::one()),
            ToneMap::Filmic => {
                let top = x * (x * N::of(2.51) + N::of(0.03));
                let bottom = x * (x * N::of(2.43) + N::of(0.59)) + N::of(0.14);
                top / bottom
            }
        };
        y.min(N::one())
    }
}

/// How a displayed value in `[0, 1]` is encoded in an image
/// ([`Effects::encoding`]), after the tone curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Encoding {
    /// `x^(1 / gamma)` with [`Effects::gamma`] (the default; 2.2 comes
    /// within 0.0084 of sRGB for linear values above 0.05, and lifts the
    /// darkest ones more: 0.001 shows as 0.043, where sRGB gives 0.013).
    #[default]
    Gamma,
    /// The sRGB transfer function exactly (IEC 61966-2-1): `12.92 x` up to
    /// `0.0031308`, `1.055 x^(1/2.4) - 0.055` above; [`Effects::gamma`] is
    /// not used.
    Srgb,
}

impl Encoding {
    /// The encoded value of `x` in `[0, 1]`, `inverse_gamma` being
    /// `1 / gamma` for [`Encoding::Gamma`].
    pub fn apply<N: Num>(self, x: N, inverse_gamma: N) -> N {
        match self {
            Encoding::Gamma => x.powf(inverse_gamma),
            Encoding::Srgb => N::select(
                x.le(N::of(0.003_130_8)),
                x * N::of(12.92),
                x.powf(N::of(1.0 / 2.4)) * N::of(1.055) - N::of(0.055),
            ),
        }
    }

    /// Whether this is the default, [`Encoding::Gamma`] (scene files leave
    /// it out).
    pub(crate) fn is_gamma(&self) -> bool {
        *self == Encoding::Gamma
    }
}

/// The displayed value in `[0, 1]` of the linear colour `linear`: scaled
/// by `scale` (`2^exposure`), through the tone curve, then encoded (raised
/// to `inverse_gamma`, or by the sRGB curve). The kernel's image and
/// [`display`] both run this one definition (the kernel's helper
/// `display_color` is printed from it).
pub fn display_formula<N: Num>(
    linear: V3<N>,
    scale: N,
    inverse_gamma: N,
    tone_map: ToneMap,
    encoding: Encoding,
) -> V3<N> {
    let channel = |c: N| encoding.apply(tone_map.apply(c * scale), inverse_gamma);
    v3(channel(linear.x), channel(linear.y), channel(linear.z))
}

/// The displayed colour, in `[0, 1]`, of a linear colour under `effects`
/// (their exposure, tone curve and encoding), in the kernel's `F32`
/// arithmetic: what the renderer's 8-bit image holds before rounding, and
/// what 16-bit images hold.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::quality::{ToneMap, display};
///
/// let effects = Effects::default().gamma(1.0).tone_map(ToneMap::Reinhard);
/// assert_eq!(display([1.0, 3.0, 0.0], &effects), [0.5, 0.75, 0.0]);
/// // One stop more light doubles the linear values first.
/// let brighter = effects.exposure(1.0);
/// assert_eq!(display([1.0, 0.0, 0.0], &brighter)[0], 2.0 / 3.0);
/// ```
#[must_use]
pub fn display(linear: [f32; 3], effects: &Effects) -> [f32; 3] {
    #[allow(clippy::cast_possible_truncation)] // the kernel's F32 constants
    let (scale, gamma) = (effects.exposure_scale() as f32, effects.gamma as f32);
    let [x, y, z] = linear;
    let out = display_formula(
        v3(x, y, z),
        scale,
        1.0 / gamma,
        effects.tone_map,
        effects.encoding,
    );
    [out.x, out.y, out.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each curve against values worked by hand.
    /// The sRGB curve against the standard's values, worked by hand: its
    /// knee (where both pieces meet), mid-grey and the ends; the gamma
    /// encoding as the power it is.
    #[test]
    fn encodings_at_known_points() {
        let srgb = |x: f64| Encoding::Srgb.apply(x, 0.0);
        for (x, want) in [
            (0.0, 0.0),
            (0.001, 0.012_92),
            (0.003_130_8, 0.040_449_936),
            (0.18, 0.461_356_129),
            (0.5, 0.735_356_983),
            (1.0, 1.0),
        ] {
            assert!((srgb(x) - want).abs() < 1e-8, "{x}: {} vs {want}", srgb(x));
        }
        // Continuous at the knee: the two pieces agree there.
        let knee = 0.003_130_8f64;
        assert!((knee * 12.92 - (1.055 * knee.powf(1.0 / 2.4) - 0.055)).abs() < 1e-7);
        assert_eq!(Encoding::Gamma.apply(0.25, 0.5), 0.5);
        // Through the display transform, for the host's 16-bit images.
        let effects = Effects::default().encoding(Encoding::Srgb);
        let shown = display([0.5, 0.18, 0.0], &effects);
        assert!((f64::from(shown[0]) - 0.735_357).abs() < 1e-5);
        assert!((f64::from(shown[1]) - 0.461_356).abs() < 1e-5);
    }

    #[test]
    fn curves_at_known_points() {
        let filmic = |x: f64| (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
        for (x, clip, reinhard) in [
            (0.0, 0.0, 0.0),
            (0.25, 0.25, 0.2),
            (1.0, 1.0, 0.5),
            (4.0, 1.0, 0.8),
        ] {
            assert_eq!(ToneMap::Clip.apply(x), clip);
            assert!((ToneMap::Reinhard.apply(x) - reinhard).abs() < 1e-15);
            assert!((ToneMap::Filmic.apply(x) - filmic(x).min(1.0)).abs() < 1e-15);
        }
        assert!((ToneMap::Filmic.apply(1.0) - 2.54 / 3.16).abs() < 1e-15);
        for t in ToneMap::ALL {
            assert_eq!(t.apply(-1.0), 0.0, "{t:?} of a negative value");
            assert_eq!(t.apply(f64::MAX).min(1.0), t.apply(f64::MAX));
            let mut last = 0.0;
            for i in 0..=4000 {
                let y = t.apply(f64::from(i) / 100.0);
                assert!(y >= last && y <= 1.0, "{t:?} is monotone in [0, 1]");
                last = y;
            }
            assert_eq!(ToneMap::from_name(&t.name().to_uppercase()), Some(t));
        }
        assert_eq!(ToneMap::from_name("aces"), None);
    }

    /// The default effects display as the kernel did before tone curves:
    /// clamped to `[0, 1]` and raised to `1 / 2.2`.
    #[test]
    fn default_display_is_clamp_and_gamma() {
        let effects = Effects::default();
        for c in [0.0f32, 0.01, 0.18, 0.5, 1.0, 7.0] {
            let want = c.clamp(0.0, 1.0).powf(1.0 / 2.2f32);
            assert_eq!(display([c, c, c], &effects)[0], want);
        }
    }
}
