//! Scene parameters: a number is either baked into the generated kernel or a
//! named dynamic slot whose value can change every frame without a rebuild.

use glam::{DVec3, Vec3};

/// One scalar parameter of a node.
///
/// Every plain number converts into a `Param` (`1.0`, `2.5f32`, `3`), so most
/// code never names this type. Use [`param`] to make a number dynamic.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Param {
    /// A constant, emitted as a literal in generated code (fastest; changing
    /// it changes the kernel source).
    Value(f64),
    /// A named value stored in the parameter buffer: it can change between
    /// frames with no recompilation. `default` is its initial value.
    Dynamic {
        /// The name used to set the value later.
        name: String,
        /// The value until it is set.
        default: f64,
    },
}

/// A dynamic scalar parameter named `name` with the initial value `default`.
///
/// Two parameters with the same name share one slot (their defaults must
/// agree).
///
/// ```
/// use fractal_sdf::prelude::*;
/// let ball = sphere(param("radius", 1.0));
/// # let _ = ball;
/// ```
#[must_use]
pub fn param(name: impl Into<String>, default: f64) -> Param {
    Param::Dynamic {
        name: name.into(),
        default,
    }
}

impl Param {
    /// The value used when no dynamic value has been set: the constant, or
    /// the dynamic parameter's default.
    #[must_use]
    pub fn default_value(&self) -> f64 {
        match self {
            Param::Value(v) => *v,
            Param::Dynamic { default, .. } => *default,
        }
    }

    /// The dynamic parameter's name, or `None` for a constant.
    #[must_use]
    pub fn name(&self) -> Option<&str> {
        match self {
            Param::Value(_) => None,
            Param::Dynamic { name, .. } => Some(name),
        }
    }
}

impl From<f64> for Param {
    fn from(v: f64) -> Self {
        Param::Value(v)
    }
}

impl From<f32> for Param {
    fn from(v: f32) -> Self {
        Param::Value(f64::from(v))
    }
}

impl From<i32> for Param {
    fn from(v: i32) -> Self {
        Param::Value(f64::from(v))
    }
}

/// A three-component parameter (an offset, a size, a colour), each
/// component a [`Param`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Param3 {
    /// The x component.
    pub x: Param,
    /// The y component.
    pub y: Param,
    /// The z component.
    pub z: Param,
}

impl Param3 {
    /// The three components in order.
    #[must_use]
    pub fn components(&self) -> [&Param; 3] {
        [&self.x, &self.y, &self.z]
    }

    /// The defaults of the three components as a vector.
    #[must_use]
    pub fn default_value(&self) -> DVec3 {
        DVec3::new(
            self.x.default_value(),
            self.y.default_value(),
            self.z.default_value(),
        )
    }
}

/// A dynamic vector parameter: three slots named `name.x`, `name.y` and
/// `name.z`.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::scene::param3;
/// let moving = sphere(0.5).translate(param3("orbit", dvec3(1.0, 0.0, 0.0)));
/// # let _ = moving;
/// ```
#[must_use]
pub fn param3(name: &str, default: impl Into<DVec3>) -> Param3 {
    let d = default.into();
    Param3 {
        x: param(format!("{name}.x"), d.x),
        y: param(format!("{name}.y"), d.y),
        z: param(format!("{name}.z"), d.z),
    }
}

impl From<DVec3> for Param3 {
    fn from(v: DVec3) -> Self {
        Param3 {
            x: v.x.into(),
            y: v.y.into(),
            z: v.z.into(),
        }
    }
}

impl From<Vec3> for Param3 {
    fn from(v: Vec3) -> Self {
        v.as_dvec3().into()
    }
}

impl From<[f64; 3]> for Param3 {
    fn from(v: [f64; 3]) -> Self {
        DVec3::from(v).into()
    }
}

impl From<[f32; 3]> for Param3 {
    fn from(v: [f32; 3]) -> Self {
        Vec3::from(v).into()
    }
}

impl From<f64> for Param3 {
    /// The same value on all three axes.
    fn from(v: f64) -> Self {
        DVec3::splat(v).into()
    }
}

impl From<[Param; 3]> for Param3 {
    fn from([x, y, z]: [Param; 3]) -> Self {
        Param3 { x, y, z }
    }
}
