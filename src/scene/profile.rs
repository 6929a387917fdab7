//! Plane shapes (circle, rectangle, rounded rectangle, stadium, vesica,
//! ellipse, polygon): the cross-sections that [`extrude`](super::extrude) and
//! [`revolve`](super::revolve) sweep into solids.

use super::param::Param;
use super::rule::{ParamSpec, Rule, spec};

/// The most vertices a [`Profile::Polygon`] may have: each edge is
/// written out in the kernel.
pub const MAX_PROFILE_VERTICES: usize = 64;

/// A shape in the plane, with coordinates `(x, y)`: the cross-section of an
/// [`extrude`](super::extrude)d or [`revolve`](super::revolve)d solid.
/// Every profile's signed distance is exact, so the solids made from them
/// are too.
///
/// ```
/// use fractal_sdf::scene::{Profile, extrude, revolve};
///
/// // A triangular prism, and a ring of square section.
/// let prism = extrude(Profile::polygon([[0.0, 0.5], [-0.4, -0.3], [0.4, -0.3]]), 0.2);
/// let ring = revolve(Profile::rect(0.1, 0.1), 0.6);
/// # let _ = (prism, ring);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, bound(deserialize = "S: serde::Deserialize<'de>"))]
#[non_exhaustive]
pub enum Profile<S = Param> {
    /// A disc of `radius` about the origin.
    Circle {
        /// Radius, at least 0.
        radius: S,
    },
    /// An axis-aligned rectangle about the origin.
    Rect {
        /// Half the width and half the height, each at least 0.
        half_extents: [S; 2],
    },
    /// A rectangle with rounded corners; its outer size is `half_extents`.
    RoundRect {
        /// Half the outer width and height, each at least 0.
        half_extents: [S; 2],
        /// Corner radius, from 0 to the smaller half extent.
        radius: S,
    },
    /// All points within `radius` of the segment from `a` to `b` (a
    /// stadium; a disc where `a == b`).
    Segment {
        /// One end of the segment.
        a: [S; 2],
        /// The other end.
        b: [S; 2],
        /// Radius, greater than 0.
        radius: S,
    },
    /// A vesica: the lens where two equal discs overlap, pointed at `(0,
    /// ±half_length)` and `half_width` wide each side of the y axis.
    Vesica {
        /// From the centre to each point, greater than 0.
        half_length: S,
        /// From the centre to each side, greater than 0 and at most
        /// `half_length` (there the vesica is a disc).
        half_width: S,
    },
    /// An axis-aligned ellipse about the origin.
    Ellipse {
        /// The semi-axes along x and y, each greater than 0.
        radii: [S; 2],
    },
    /// A closed polygon through `vertices`, in order (either winding), of 3
    /// to [`MAX_PROFILE_VERTICES`] vertices. Where its edges cross, a point
    /// is inside when a ray from it crosses the edges an odd number of
    /// times.
    Polygon {
        /// The corners, in order around the polygon.
        vertices: Vec<[S; 2]>,
    },
}

impl Profile {
    /// A disc of `radius` about the origin.
    #[must_use]
    pub fn circle(radius: impl Into<Param>) -> Self {
        Profile::Circle {
            radius: radius.into(),
        }
    }

    /// A rectangle of half width `half_x` and half height `half_y`.
    #[must_use]
    pub fn rect(half_x: impl Into<Param>, half_y: impl Into<Param>) -> Self {
        Profile::Rect {
            half_extents: [half_x.into(), half_y.into()],
        }
    }

    /// A rectangle of half width `half_x` and half height `half_y` with
    /// corners rounded by `radius`.
    #[must_use]
    pub fn round_rect(
        half_x: impl Into<Param>,
        half_y: impl Into<Param>,
        radius: impl Into<Param>,
    ) -> Self {
        Profile::RoundRect {
            half_extents: [half_x.into(), half_y.into()],
            radius: radius.into(),
        }
    }

    /// All points within `radius` of the segment from `a` to `b`.
    #[must_use]
    pub fn segment(a: [f64; 2], b: [f64; 2], radius: impl Into<Param>) -> Self {
        Profile::Segment {
            a: a.map(Param::from),
            b: b.map(Param::from),
            radius: radius.into(),
        }
    }

    /// The vesica pointed at `(0, ±half_length)`, `half_width` wide each side
    /// of the y axis.
    #[must_use]
    pub fn vesica(half_length: impl Into<Param>, half_width: impl Into<Param>) -> Self {
        Profile::Vesica {
            half_length: half_length.into(),
            half_width: half_width.into(),
        }
    }

    /// The ellipse of semi-axes `a` along x and `b` along y.
    #[must_use]
    pub fn ellipse(a: impl Into<Param>, b: impl Into<Param>) -> Self {
        Profile::Ellipse {
            radii: [a.into(), b.into()],
        }
    }

    /// The polygon through `vertices`, in order.
    #[must_use]
    pub fn polygon(vertices: impl IntoIterator<Item = [f64; 2]>) -> Self {
        Profile::Polygon {
            vertices: vertices.into_iter().map(|v| v.map(Param::from)).collect(),
        }
    }
}

impl<S> Profile<S> {
    /// Rebuilds the profile with every number converted by `f`, which sees
    /// each one's name (`profile.vertices[2].x`) and rule.
    pub(crate) fn try_map<S2, E>(
        &self,
        f: &mut impl FnMut(&S, ParamSpec<'_>) -> Result<S2, E>,
    ) -> Result<Profile<S2>, E> {
        use Rule::{Finite, NonNegative, Positive};
        Ok(match self {
            Profile::Circle { radius } => Profile::Circle {
                radius: f(radius, spec("profile.radius", NonNegative))?,
            },
            Profile::Rect { half_extents } => Profile::Rect {
                half_extents: two(f, half_extents, "profile.half_extents", NonNegative)?,
            },
            Profile::RoundRect {
                half_extents,
                radius,
            } => Profile::RoundRect {
                half_extents: two(f, half_extents, "profile.half_extents", NonNegative)?,
                radius: f(radius, spec("profile.radius", NonNegative))?,
            },
            Profile::Segment { a, b, radius } => Profile::Segment {
                a: two(f, a, "profile.a", Finite)?,
                b: two(f, b, "profile.b", Finite)?,
                radius: f(radius, spec("profile.radius", Positive))?,
            },
            Profile::Vesica {
                half_length,
                half_width,
            } => Profile::Vesica {
                half_length: f(half_length, spec("profile.half_length", Positive))?,
                half_width: f(half_width, spec("profile.half_width", Positive))?,
            },
            Profile::Ellipse { radii } => Profile::Ellipse {
                radii: two(f, radii, "profile.radii", Positive)?,
            },
            Profile::Polygon { vertices } => Profile::Polygon {
                vertices: vertices
                    .iter()
                    .enumerate()
                    .map(|(i, v)| two(f, v, &format!("profile.vertices[{i}]"), Finite))
                    .collect::<Result<_, _>>()?,
            },
        })
    }

    /// The profile with every number converted by `f`.
    pub(crate) fn map<S2>(&self, mut f: impl FnMut(&S) -> S2) -> Profile<S2> {
        let mapped: Result<_, std::convert::Infallible> = self.try_map(&mut |s, _| Ok(f(s)));
        match mapped {
            Ok(p) => p,
        }
    }
}

impl Profile<f64> {
    /// The radius of the disc about the origin that holds the profile.
    pub(crate) fn extent(&self) -> f64 {
        let length = |v: &[f64; 2]| v[0].hypot(v[1]);
        match self {
            Profile::Circle { radius } => *radius,
            Profile::Rect { half_extents } | Profile::RoundRect { half_extents, .. } => {
                length(half_extents)
            }
            Profile::Segment { a, b, radius } => length(a).max(length(b)) + radius,
            Profile::Ellipse { radii } => radii[0].max(radii[1]),
            Profile::Vesica { half_length, .. } => *half_length,
            Profile::Polygon { vertices } => vertices.iter().map(length).fold(0.0, f64::max),
        }
    }

    /// Twice the polygon's signed area (the shoelace sum); `None` for the
    /// other profiles.
    pub(crate) fn twice_area(&self) -> Option<f64> {
        let Profile::Polygon { vertices } = self else {
            return None;
        };
        let n = vertices.len();
        Some(
            (0..n)
                .map(|i| {
                    let (a, b) = (vertices[i], vertices[(i + 1) % n]);
                    a[0] * b[1] - a[1] * b[0]
                })
                .sum(),
        )
    }
}

/// The two components of a point, named `name.x` and `name.y`.
fn two<S, S2, E>(
    f: &mut impl FnMut(&S, ParamSpec<'_>) -> Result<S2, E>,
    v: &[S; 2],
    name: &str,
    rule: Rule,
) -> Result<[S2; 2], E> {
    let [x, y] = v;
    Ok([
        f(x, spec(&format!("{name}.x"), rule))?,
        f(y, spec(&format!("{name}.y"), rule))?,
    ])
}
