//! Orbit-trap colouring: a fractal painted by how near its orbit comes to
//! a shape ([`Trap`]), through a colour gradient ([`Palette`]).
//!
//! Every fractal iterates a map from the point it is asked about. An
//! orbit trap is a shape in the fractal's own coordinates; the trap value
//! of a point is the smallest distance from its orbit (the point itself
//! and each iterate within the fractal's bailout) to the shape, or for
//! [`Trap::Iterations`] the orbit's smooth iteration count. Points near
//! each other on the surface have similar orbits, so the value paints
//! bands and whorls that follow the fractal's structure. [`Node::orbit_trap`](super::Node::orbit_trap)
//! maps the values from `near` to `far` onto a palette and makes that the
//! fractal's colour: in every render, under every material, and in mesh
//! vertex colours.
//!
//! ```
//! use fractal_sdf::prelude::*;
//! use fractal_sdf::scene::{Palette, Trap, param3};
//!
//! // Bands by the distance of the orbit to the plane z = 0.
//! let bulb = mandelbulb(8.0).orbit_trap(Trap::plane([0.0, 0.0, 1.0], 0.0), Palette::fire());
//! // A gradient of your own, from a trap animated by a parameter.
//! let sponge = menger(4).orbit_trap(
//!     Trap::sphere(param3("trap_centre", [0.5, 0.5, 0.5]), 0.25),
//!     Palette::gradient([(0.0, [0.02, 0.02, 0.1]), (1.0, [0.9, 0.8, 0.5])]),
//! );
//! # let _ = (bulb, sponge);
//! ```

use super::param::{Param, Param3};
use super::rule::{ParamSpec, Rule, spec};
use crate::math::{Num, V3, v3};

/// A palette holds at most this many stops.
pub const MAX_PALETTE_STOPS: usize = 16;

/// The shape an orbit is measured against, in the fractal's own
/// coordinates. The trap value is the smallest distance from the orbit to
/// it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub enum Trap<S = Param, V = Param3> {
    /// A point: the orbit's distance to `centre`.
    Point {
        /// The point.
        centre: V,
    },
    /// A sphere's surface: `| |z − centre| − radius |`.
    Sphere {
        /// Its centre.
        centre: V,
        /// Its radius, at least 0.
        radius: S,
    },
    /// A plane, `normal · z + offset = 0` (`normal` normalised), as the
    /// scene's [`plane`](super::plane) writes it.
    Plane {
        /// The plane's normal, not zero.
        normal: V,
        /// Minus its signed distance from the origin along the normal.
        offset: S,
    },
    /// A line through `point` along `direction` (normalised).
    Line {
        /// A point on the line.
        point: V,
        /// Its direction, not zero.
        direction: V,
    },
    /// Not a shape: the iteration count, smoothed. The value is the sum
    /// of `e^(−|z|)` over the orbit, so each point near the origin adds
    /// about 1 and a point that has escaped almost nothing: it grows with
    /// the iterations the orbit spends near the set, and unlike the count
    /// itself it has no steps where the orbit escapes one iteration
    /// sooner. Set the range to the values wanted (up to the fractal's
    /// iteration count, plus 1 for the point itself).
    Iterations,
}

impl Trap {
    /// A point trap.
    #[must_use]
    pub fn point(centre: impl Into<Param3>) -> Trap {
        Trap::Point {
            centre: centre.into(),
        }
    }

    /// A sphere trap: the distance to the sphere's surface.
    #[must_use]
    pub fn sphere(centre: impl Into<Param3>, radius: impl Into<Param>) -> Trap {
        Trap::Sphere {
            centre: centre.into(),
            radius: radius.into(),
        }
    }

    /// A plane trap, `normal · z + offset = 0` (the convention of the
    /// scene's [`plane`](super::plane)).
    #[must_use]
    pub fn plane(normal: impl Into<Param3>, offset: impl Into<Param>) -> Trap {
        Trap::Plane {
            normal: normal.into(),
            offset: offset.into(),
        }
    }

    /// A line trap through `point` along `direction`.
    #[must_use]
    pub fn line(point: impl Into<Param3>, direction: impl Into<Param3>) -> Trap {
        Trap::Line {
            point: point.into(),
            direction: direction.into(),
        }
    }
}

impl<S, V> Trap<S, V> {
    /// The trap's name, as in scene files.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Trap::Point { .. } => "Point",
            Trap::Sphere { .. } => "Sphere",
            Trap::Plane { .. } => "Plane",
            Trap::Line { .. } => "Line",
            Trap::Iterations => "Iterations",
        }
    }

    /// Rebuilds the trap with every value converted, in the order of its
    /// fields (each named `trap.field`).
    pub(crate) fn try_map<S2, V2, E>(
        &self,
        scalar: &mut impl FnMut(&S, ParamSpec<'static>) -> Result<S2, E>,
        vector: &mut impl FnMut(&V, ParamSpec<'static>) -> Result<V2, E>,
    ) -> Result<Trap<S2, V2>, E> {
        use Rule::{Direction, Finite, NonNegative};
        Ok(match self {
            Trap::Point { centre } => Trap::Point {
                centre: vector(centre, spec("trap.centre", Finite))?,
            },
            Trap::Sphere { centre, radius } => Trap::Sphere {
                centre: vector(centre, spec("trap.centre", Finite))?,
                radius: scalar(radius, spec("trap.radius", NonNegative))?,
            },
            Trap::Plane { normal, offset } => Trap::Plane {
                normal: vector(normal, spec("trap.normal", Direction))?,
                offset: scalar(offset, spec("trap.offset", Finite))?,
            },
            Trap::Line { point, direction } => Trap::Line {
                point: vector(point, spec("trap.point", Finite))?,
                direction: vector(direction, spec("trap.direction", Direction))?,
            },
            Trap::Iterations => Trap::Iterations,
        })
    }

    /// The trap's direction (a plane's normal, a line's direction), which
    /// must not be zero.
    pub(crate) fn direction(&self) -> Option<(&'static str, &V)> {
        match self {
            Trap::Plane { normal, .. } => Some(("trap.normal", normal)),
            Trap::Line { direction, .. } => Some(("trap.direction", direction)),
            Trap::Point { .. } | Trap::Sphere { .. } | Trap::Iterations => None,
        }
    }

    /// The trap's direction, mutably.
    pub(crate) fn direction_mut(&mut self) -> Option<&mut V> {
        match self {
            Trap::Plane { normal, .. } => Some(normal),
            Trap::Line { direction, .. } => Some(direction),
            Trap::Point { .. } | Trap::Sphere { .. } | Trap::Iterations => None,
        }
    }
}

/// A colour gradient over `[0, 1]`: stops at increasing positions, each a
/// linear RGB colour, linearly interpolated between them and constant
/// beyond the first and the last.
///
/// The named palettes ([`Palette::fire`], [`Palette::viridis`], ...) are
/// defined by colours as they should look in the image and stored
/// linearised for the default output gamma (2.2), so they show as designed
/// there.
#[derive(Debug, Clone, PartialEq)]
pub struct Palette {
    stops: Vec<(f64, [f64; 3])>,
}

/// A palette's stops, `(position, RGB)`.
type Stops = &'static [(f64, [f64; 3])];

/// The named palettes, as display colours (see [`Palette`]).
const NAMED: [(&str, Stops); 7] = [
    (
        "fire",
        &[
            (0.0, [0.03, 0.0, 0.0]),
            (0.3, [0.55, 0.04, 0.0]),
            (0.6, [0.95, 0.42, 0.02]),
            (0.85, [1.0, 0.84, 0.3]),
            (1.0, [1.0, 1.0, 0.88]),
        ],
    ),
    (
        "ocean",
        &[
            (0.0, [0.01, 0.04, 0.16]),
            (0.35, [0.0, 0.26, 0.46]),
            (0.7, [0.1, 0.63, 0.68]),
            (1.0, [0.86, 0.96, 0.9]),
        ],
    ),
    (
        "viridis",
        &[
            (0.0, [0.267, 0.005, 0.329]),
            (0.25, [0.231, 0.322, 0.545]),
            (0.5, [0.129, 0.569, 0.549]),
            (0.75, [0.369, 0.788, 0.384]),
            (1.0, [0.993, 0.906, 0.144]),
        ],
    ),
    (
        "magma",
        &[
            (0.0, [0.0, 0.0, 0.016]),
            (0.25, [0.317, 0.071, 0.486]),
            (0.5, [0.718, 0.216, 0.475]),
            (0.75, [0.988, 0.537, 0.38]),
            (1.0, [0.988, 0.992, 0.749]),
        ],
    ),
    (
        "copper",
        &[
            (0.0, [0.08, 0.03, 0.01]),
            (0.45, [0.62, 0.3, 0.14]),
            (0.8, [0.93, 0.68, 0.45]),
            (1.0, [1.0, 0.92, 0.8]),
        ],
    ),
    (
        "rainbow",
        &[
            (0.0, [0.9, 0.1, 0.1]),
            (0.2, [0.95, 0.6, 0.05]),
            (0.4, [0.85, 0.9, 0.1]),
            (0.6, [0.1, 0.8, 0.3]),
            (0.8, [0.1, 0.4, 0.9]),
            (1.0, [0.55, 0.15, 0.8]),
        ],
    ),
    ("grey", &[(0.0, [0.0, 0.0, 0.0]), (1.0, [1.0, 1.0, 1.0])]),
];

/// The output gamma the named palettes are linearised for.
const NAMED_GAMMA: f64 = 2.2;

impl Palette {
    /// A gradient of `(position, linear RGB)` stops. Positions increase
    /// within `[0, 1]`; colours are at least 0; at most
    /// [`MAX_PALETTE_STOPS`] stops. Compiling a scene checks this.
    #[must_use]
    pub fn gradient(stops: impl IntoIterator<Item = (f64, [f64; 3])>) -> Palette {
        Palette {
            stops: stops.into_iter().collect(),
        }
    }

    /// The named palette, or `None`: one of [`Palette::names`].
    #[must_use]
    pub fn named(name: &str) -> Option<Palette> {
        NAMED.iter().find(|(n, _)| *n == name).map(|(_, stops)| {
            Palette::gradient(
                stops
                    .iter()
                    .map(|&(t, c)| (t, c.map(|v| v.powf(NAMED_GAMMA)))),
            )
        })
    }

    /// The names [`Palette::named`] knows.
    pub fn names() -> impl Iterator<Item = &'static str> {
        NAMED.iter().map(|(n, _)| *n)
    }

    /// This palette's name, where it is one of the named palettes.
    #[must_use]
    pub fn name(&self) -> Option<&'static str> {
        Palette::names().find(|n| Palette::named(n).as_ref() == Some(self))
    }

    /// Black through deep red and orange to pale yellow.
    #[must_use]
    pub fn fire() -> Palette {
        Palette::named("fire").expect("a named palette")
    }

    /// Deep blue through teal to sea foam.
    #[must_use]
    pub fn ocean() -> Palette {
        Palette::named("ocean").expect("a named palette")
    }

    /// Purple through blue and green to yellow, rising in lightness.
    #[must_use]
    pub fn viridis() -> Palette {
        Palette::named("viridis").expect("a named palette")
    }

    /// Black through purple and rose to pale yellow.
    #[must_use]
    pub fn magma() -> Palette {
        Palette::named("magma").expect("a named palette")
    }

    /// Dark brown through copper to a pale gold.
    #[must_use]
    pub fn copper() -> Palette {
        Palette::named("copper").expect("a named palette")
    }

    /// Red, orange, yellow, green, blue, violet.
    #[must_use]
    pub fn rainbow() -> Palette {
        Palette::named("rainbow").expect("a named palette")
    }

    /// Black to white.
    #[must_use]
    pub fn grey() -> Palette {
        Palette::named("grey").expect("a named palette")
    }

    /// The stops, `(position, linear RGB)`.
    #[must_use]
    pub fn stops(&self) -> &[(f64, [f64; 3])] {
        &self.stops
    }

    /// The colour at `t` (clamped to the stops), for a palette that
    /// passes the checks compiling a scene makes (stops at increasing
    /// positions).
    #[must_use]
    pub fn color(&self, t: f64) -> [f64; 3] {
        let c = self.at(t);
        [c.x, c.y, c.z]
    }

    /// The colour at `t`, written once for the CPU reference and the
    /// kernels: the first stop's colour up to its position, then each
    /// segment's linear ramp added in turn, so the result is the
    /// piecewise-linear gradient with no branch (black with no stops).
    #[must_use]
    pub fn at<T: Num>(&self, t: T) -> V3<T> {
        let color = |c: [f64; 3]| v3(T::of(c[0]), T::of(c[1]), T::of(c[2]));
        let Some(&(_, first)) = self.stops.first() else {
            return V3::splat(T::zero());
        };
        let mut out = color(first);
        for pair in self.stops.windows(2) {
            let [(t0, c0), (t1, c1)] = [pair[0], pair[1]];
            let w = ((t - T::of(t0)) * T::of(1.0 / (t1 - t0))).clamp(T::zero(), T::one());
            out = out + color([c1[0] - c0[0], c1[1] - c0[1], c1[2] - c0[2]]) * w;
        }
        out
    }

    /// The palette position of the trap value `value`: `near` at 0, `far`
    /// at 1, clamped to `[0, 1]` (a `far` below `near` reverses it; equal
    /// ones are refused when a scene compiles, and ends nearer than the
    /// smallest size are taken that far apart).
    #[must_use]
    pub fn position<T: Num>(value: T, near: T, far: T) -> T {
        let span = far - near;
        let least = T::select(span.lt(T::zero()), -T::tiny(), T::tiny());
        let span = T::select(span.abs().lt(T::tiny()), least, span);
        ((value - near) / span).clamp(T::zero(), T::one())
    }

    /// Why the palette cannot be used, if it cannot.
    pub(crate) fn check(&self) -> Result<(), String> {
        let n = self.stops.len();
        if n == 0 || n > MAX_PALETTE_STOPS {
            return Err(format!(
                "has {n} stops; a palette has 1 to {MAX_PALETTE_STOPS}"
            ));
        }
        let mut last = f64::NEG_INFINITY;
        for (i, &(t, c)) in self.stops.iter().enumerate() {
            if !(0.0..=1.0).contains(&t) {
                return Err(format!("stop {i} is at {t}; positions are in [0, 1]"));
            }
            if t <= last {
                return Err(format!(
                    "stop {i} is at {t}, not after the stop before it ({last}); positions increase"
                ));
            }
            if let Some(v) = c.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(format!(
                    "stop {i}'s colour has {v}; colours are finite and at least 0"
                ));
            }
            last = t;
        }
        Ok(())
    }
}

/// How a fractal is coloured by its orbit trap: the trap, the palette,
/// and the trap values that reach the palette's ends (see
/// [`Node::orbit_trap`](super::Node::orbit_trap)).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct OrbitColoring<S = Param, V = Param3> {
    /// The shape the orbit is measured against.
    pub trap: Trap<S, V>,
    /// The colours.
    pub palette: Palette,
    /// The trap value shown as the palette's start (position 0).
    pub near: S,
    /// The trap value shown as its end (position 1); not `near`. Below
    /// `near` (above `far`) the colour is the first (last) stop's; `far`
    /// below `near` reverses the palette.
    pub far: S,
}

impl OrbitColoring {
    /// Trap values from 0 to 1 span the palette.
    #[must_use]
    pub fn new(trap: Trap, palette: Palette) -> OrbitColoring {
        OrbitColoring {
            trap,
            palette,
            near: Param::from(0.0),
            far: Param::from(1.0),
        }
    }

    /// The trap values shown at the palette's two ends.
    #[must_use]
    pub fn range(mut self, near: impl Into<Param>, far: impl Into<Param>) -> OrbitColoring {
        self.near = near.into();
        self.far = far.into();
        self
    }
}

impl<S, V> OrbitColoring<S, V> {
    /// Rebuilds the colouring with every value converted: the trap's,
    /// then `near` and `far`.
    pub(crate) fn try_map<S2, V2, E>(
        &self,
        scalar: &mut impl FnMut(&S, ParamSpec<'static>) -> Result<S2, E>,
        vector: &mut impl FnMut(&V, ParamSpec<'static>) -> Result<V2, E>,
    ) -> Result<OrbitColoring<S2, V2>, E> {
        Ok(OrbitColoring {
            trap: self.trap.try_map(scalar, vector)?,
            palette: self.palette.clone(),
            near: scalar(&self.near, spec("near", Rule::Finite))?,
            far: scalar(&self.far, spec("far", Rule::Finite))?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_named_palette_is_valid_and_knows_its_name() {
        for name in Palette::names() {
            let p = Palette::named(name).unwrap();
            assert_eq!(p.check(), Ok(()), "{name}");
            assert_eq!(p.name(), Some(name));
        }
        assert_eq!(Palette::named("plaid"), None);
        assert_eq!(Palette::gradient([(0.0, [1.0; 3])]).name(), None);
    }

    #[test]
    fn a_gradient_interpolates_linearly_and_clamps() {
        let p = Palette::gradient([(0.25, [0.0, 1.0, 0.0]), (0.75, [1.0, 0.0, 0.5])]);
        assert_eq!(p.color(0.0), [0.0, 1.0, 0.0]);
        assert_eq!(p.color(0.5), [0.5, 0.5, 0.25]);
        assert_eq!(p.color(2.0), [1.0, 0.0, 0.5]);
    }

    #[test]
    fn bad_palettes_say_why() {
        let empty = Palette::gradient([]);
        assert!(empty.check().unwrap_err().contains("0 stops"));
        let back = Palette::gradient([(0.5, [0.0; 3]), (0.2, [1.0; 3])]);
        assert!(back.check().unwrap_err().contains("positions increase"));
        let out = Palette::gradient([(1.5, [0.0; 3])]);
        assert!(out.check().unwrap_err().contains("[0, 1]"));
        let neg = Palette::gradient([(0.0, [0.0, -1.0, 0.0])]);
        assert!(neg.check().unwrap_err().contains("at least 0"));
    }
}
