//! Scenes as typed Rust values: geometry ([`Node`]), lights and a camera.
//!
//! Building never fails; [`Scene::compile`] validates and lowers a scene
//! once, reporting the first bad value as a typed [`Error`] naming the
//! node's path and the parameter.

mod build;
mod custom;
mod environment;
mod fractal;
mod hybrid;
mod inside;
mod kleinian;
mod material;
pub(crate) mod names;
mod node;
mod param;
mod profile;
mod rule;
mod stereo;
mod trap;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

pub use build::{
    box_frame, capped_cone, capped_torus, capsule, cone, cone_between, cuboid, cut_hollow_sphere,
    cut_sphere, cylinder, cylinder_between, death_star, ellipsoid, extrude, hex_prism,
    infinite_cone, infinite_cylinder, julia, kifs, link, mandelbox, mandelbulb, menger, octahedron,
    octahedron_bound, plane, pyramid, quad, revolve, rhombus, round_box, round_cone,
    round_cone_between, rounded_cylinder, sierpinski, solid_angle, sphere, torus, tri_prism,
    triangle,
};
pub use custom::{
    CpuDistance, CpuInside, CustomShape, INSIDE_HUGE, InsideBounds, MAX_INSIDE_REACH,
};
#[cfg(feature = "opencl")]
pub(crate) use environment::direction as environment_direction;
pub use environment::{Environment, EnvironmentMap, MAX_ENVIRONMENT_SIDE};
pub use fractal::{Kifs, KifsFold, Mandelbox, Mandelbulb, Menger, QuaternionJulia, Sierpinski};
pub use hybrid::{Hybrid, HybridOp, HybridStage, MAX_HYBRID_OPS};
pub use inside::{
    BRUTE_MAX_STEPS, InsideShape, MANDELBOX_BAILOUT, MANDELBOX_HALF_SIDE, MANDELBULB_BAILOUT,
    mandelbox_contains, mandelbulb_contains,
};
pub use kleinian::{PseudoKleinian, pseudo_kleinian};
pub(crate) use material::MATERIAL_SPECS;
pub use material::{DEFAULT_MATERIAL, MATERIAL_LEN, Material};
pub(crate) use node::Mapper;
pub use node::{
    Axis, CsgOp, Kind, MAX_ESCAPE_ITERATIONS, MAX_FOLD_ITERATIONS, MAX_SOLID_ANGLE, MAX_WARP_RATE,
    Node, NodeKind,
};
pub use param::{Param, Param3, param, param3};
pub use profile::{MAX_PROFILE_VERTICES, Profile};
pub use rule::{ParamSpec, Rule};
pub use stereo::{Stereo, StereoLayout};
pub use trap::{MAX_PALETTE_STOPS, OrbitColoring, Palette, Trap};

use crate::error::{Error, Result, fmt_value};
use crate::math::{F64_LIMITS, Magnitude, normalize};

/// How the camera projects the scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub enum Projection {
    /// Perspective with a vertical field of view in degrees, in (0, 180).
    Perspective {
        /// Vertical field of view in degrees.
        fov_y_degrees: f64,
    },
    /// Orthographic: parallel rays, `height` scene units visible vertically.
    Orthographic {
        /// Visible height in scene units, greater than 0.
        height: f64,
    },
}

/// A look-at camera.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct Camera {
    /// Where the camera is.
    pub position: DVec3,
    /// The point it looks at.
    pub target: DVec3,
    /// The approximate up direction (made orthogonal to the view).
    pub up: DVec3,
    /// Perspective or orthographic.
    pub projection: Projection,
    /// The radius of a thin lens, in scene units: points off the plane in
    /// focus blur into discs that grow with it (depth of field). 0, the
    /// default, is a pinhole: everything is sharp, and the image is the
    /// same as without a lens. The blur is sampled by supersampling or
    /// progressive passes.
    pub aperture: f64,
    /// The distance along the view at which the lens is in focus; `None`
    /// (the default) focuses on the target.
    pub focus_distance: Option<f64>,
    /// Lens shift: the image window moved sideways and up without turning
    /// the camera, in units of half the image's height (`(0, 1)` moves it
    /// up by half the image). Off-axis stereo eyes use it
    /// ([`Camera::eyes`]); 0 by default.
    pub shift: DVec2,
}

impl Camera {
    /// A perspective camera at `position` looking at `target`, y up, with a
    /// 45° vertical field of view.
    #[must_use]
    pub fn look_at(position: impl Into<DVec3>, target: impl Into<DVec3>) -> Self {
        Camera {
            position: position.into(),
            target: target.into(),
            up: DVec3::Y,
            projection: Projection::Perspective {
                fov_y_degrees: 45.0,
            },
            aperture: 0.0,
            focus_distance: None,
            shift: DVec2::ZERO,
        }
    }

    /// Sets the vertical field of view in degrees (perspective).
    #[must_use]
    pub fn fov(mut self, fov_y_degrees: f64) -> Self {
        self.projection = Projection::Perspective { fov_y_degrees };
        self
    }

    /// Switches to an orthographic projection showing `height` units.
    #[must_use]
    pub fn orthographic(mut self, height: f64) -> Self {
        self.projection = Projection::Orthographic { height };
        self
    }

    /// Sets the up direction.
    #[must_use]
    pub fn up(mut self, up: impl Into<DVec3>) -> Self {
        self.up = up.into();
        self
    }

    /// Gives the camera a thin lens of radius `aperture` (scene units),
    /// in focus at the target unless [`Camera::focus`] says otherwise.
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// let camera = Camera::look_at(dvec3(0.0, 0.0, 4.0), DVec3::ZERO).lens(0.05).focus(3.0);
    /// assert_eq!(camera.focus_distance(), 3.0);
    /// ```
    #[must_use]
    pub fn lens(mut self, aperture: f64) -> Self {
        self.aperture = aperture;
        self
    }

    /// Sets the distance along the view that is in focus.
    #[must_use]
    pub fn focus(mut self, distance: f64) -> Self {
        self.focus_distance = Some(distance);
        self
    }

    /// Sets the lens shift ([`Camera::shift`]).
    #[must_use]
    pub fn shifted(mut self, shift: impl Into<DVec2>) -> Self {
        self.shift = shift.into();
        self
    }

    /// The distance along the view that is in focus:
    /// [`Camera::focus_distance`], or the target's distance.
    #[must_use]
    pub fn focus_distance(&self) -> f64 {
        self.focus_distance
            .unwrap_or_else(|| (self.target - self.position).length())
    }

    /// The left and right eyes of a stereo pair around this camera, with
    /// off-axis (asymmetric) frusta rather than turned-in ones: each eye
    /// moves `separation / 2` sideways and looks the same way, and its
    /// image window shifts back towards the centre so that the two windows
    /// coincide `convergence` along the view. Points at that distance
    /// appear at the same place in both images; nearer points are seen
    /// further right by the left eye than by the right (crossed
    /// disparity), farther points further left.
    ///
    /// # Errors
    /// [`Error::Camera`] for an orthographic camera (parallel rays see no
    /// depth), a separation that is negative or not finite, or a
    /// convergence distance that is not above 0; any error of
    /// [`Camera::validate`].
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// let [left, right] = Camera::default().eyes(0.1, 3.5)?;
    /// assert!(left.position.x < right.position.x);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    pub fn eyes(&self, separation: f64, convergence: f64) -> Result<[Camera; 2]> {
        let (right, _, _) = self.basis()?;
        let bad = |reason: String| Err(Error::Camera { reason });
        let Projection::Perspective { fov_y_degrees } = self.projection else {
            return bad("stereo needs a perspective camera".into());
        };
        // The convergence first: a default separation is made from it.
        if !(convergence > 0.0 && convergence.is_finite()) {
            return bad(format!(
                "convergence distance must be finite and > 0, got {}",
                fmt_value(convergence)
            ));
        }
        if !(separation >= 0.0 && separation.is_finite()) {
            return bad(format!(
                "eye separation must be finite and >= 0, got {}",
                fmt_value(separation)
            ));
        }
        // Half the window's height at unit distance: the shift's unit.
        let half_h = (fov_y_degrees.to_radians() * 0.5).tan();
        let eye = |side: f64| {
            let offset = right * (side * separation * 0.5);
            Camera {
                position: self.position + offset,
                target: self.target + offset,
                shift: self.shift
                    + DVec2::new(-side * separation * 0.5 / (convergence * half_h), 0.0),
                ..*self
            }
        };
        Ok([eye(-1.0), eye(1.0)])
    }

    /// The orthonormal camera basis `(right, up, forward)`, normalised
    /// robustly ([`math::normalize`](crate::math::normalize)): an `up` or a
    /// view of any finite length gives the same basis.
    ///
    /// # Errors
    /// [`Error::Camera`] if the camera is degenerate (see [`Camera::validate`]).
    pub fn basis(&self) -> Result<(DVec3, DVec3, DVec3)> {
        self.validate()?;
        let unit = |v: DVec3| normalize(v).expect("validate refuses zero vectors");
        let forward = unit(self.target - self.position);
        let right = unit(forward.cross(unit(self.up)));
        let up = right.cross(forward);
        Ok((right, up, forward))
    }

    /// Checks that the camera can form an image: finite vectors, target
    /// different from position, up not zero nor parallel to the view (its
    /// length does not matter), field of view in (0°, 180°), orthographic
    /// height > 0, aperture >= 0, focus distance > 0, finite shift; and that position, target and height are within the
    /// magnitudes the CPU reference and an `F64` kernel compute with
    /// ([`Precision::limits`](crate::quality::Precision::limits)). A
    /// renderer also checks them against its own precision.
    ///
    /// # Errors
    /// [`Error::Camera`] saying what is wrong; [`Error::Precision`] for a
    /// value beyond the `F64` limits.
    pub fn validate(&self) -> Result<()> {
        let bad = |reason: &str| {
            Err(Error::Camera {
                reason: reason.into(),
            })
        };
        if !(self.position.is_finite() && self.target.is_finite() && self.up.is_finite()) {
            return bad("position, target and up must be finite");
        }
        for (name, v) in [("position", self.position), ("target", self.target)] {
            within("camera", name, v, Magnitude::Coordinate)?;
        }
        let view = self.target - self.position;
        if view.length() == 0.0 {
            return bad("target equals position");
        }
        if view.length() <= f64::EPSILON * self.position.length().max(1.0) {
            return Err(Error::Camera {
                reason: format!(
                    "position {} is too large for a target {} away: at that magnitude the \
                     view's direction cannot be resolved (move the camera, or rescale the scene)",
                    fmt_vec(self.position),
                    fmt_value(view.length())
                ),
            });
        }
        let Some(up) = normalize(self.up) else {
            return bad("up is zero");
        };
        let forward = normalize(view).expect("a view longer than zero");
        if forward.cross(up).length() < 1e-9 {
            return bad("up is parallel to the view direction");
        }
        match self.projection {
            Projection::Perspective { fov_y_degrees } => {
                if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
                    return Err(Error::Camera {
                        reason: format!(
                            "vertical field of view must be in (0, 180) degrees, got {}",
                            fmt_value(fov_y_degrees)
                        ),
                    });
                }
            }
            Projection::Orthographic { height } => {
                if !(height > 0.0 && height.is_finite()) {
                    return Err(Error::Camera {
                        reason: format!(
                            "orthographic height must be > 0, got {}",
                            fmt_value(height)
                        ),
                    });
                }
                within_scalar("camera", "orthographic height", height, Magnitude::Size)?;
            }
        }
        if !(self.aperture >= 0.0 && self.aperture.is_finite()) {
            return bad(&format!(
                "aperture must be finite and >= 0, got {}",
                fmt_value(self.aperture)
            ));
        }
        within_scalar("camera", "aperture", self.aperture, Magnitude::Size)?;
        if let Some(focus) = self.focus_distance {
            if !(focus > 0.0 && focus.is_finite()) {
                return bad(&format!(
                    "focus distance must be finite and > 0, got {}",
                    fmt_value(focus)
                ));
            }
            within_scalar("camera", "focus distance", focus, Magnitude::Size)?;
        }
        if !self.shift.is_finite() {
            return bad("lens shift must be finite");
        }
        for (value, axis) in self.shift.to_array().into_iter().zip(["x", "y"]) {
            within_scalar("camera", &format!("shift.{axis}"), value, Magnitude::Size)?;
        }
        Ok(())
    }
}

/// A vector as a message writes it, each component as [`fmt_value`] does.
fn fmt_vec(v: DVec3) -> String {
    format!(
        "({}, {}, {})",
        fmt_value(v.x),
        fmt_value(v.y),
        fmt_value(v.z)
    )
}

impl Default for Camera {
    /// Looking at the origin from (0, 0.5, 3.5).
    fn default() -> Self {
        Camera::look_at(DVec3::new(0.0, 0.5, 3.5), DVec3::ZERO)
    }
}

/// Where light comes from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub enum LightSource {
    /// Parallel light, like the sun; `direction` points from the scene
    /// towards the light.
    Directional {
        /// Direction towards the light (normalised when rendering).
        direction: DVec3,
    },
    /// Light from a point, falling off with the square of the distance.
    Point {
        /// The light's position.
        position: DVec3,
    },
    /// Light from a glowing ball: as bright as a point light of the same
    /// intensity at its centre wherever the whole ball is in view (its
    /// radiance is the intensity over the radius squared), with the soft
    /// shadows of its size under global illumination. Direct lighting
    /// treats it as that point light, with the light's `softness`. The
    /// ball itself is not drawn.
    Sphere {
        /// The ball's centre.
        position: DVec3,
        /// The ball's radius, above 0.
        radius: f64,
    },
    /// Light from a glowing rectangle, on the side its normal `u × v`
    /// faces: seen square on from `d` away it is as bright as a point light
    /// of the same intensity at its centre, and dims with the cosine of the
    /// angle it is seen at (a Lambertian emitter of radiance
    /// `π intensity / area`). Under global illumination its shadows have
    /// the rectangle's size; direct lighting treats it as that point light
    /// on its lit side, with the light's `softness`. The rectangle itself
    /// is not drawn.
    Rect {
        /// The rectangle's centre.
        position: DVec3,
        /// Half of one side, from the centre to the middle of an edge.
        u: DVec3,
        /// Half of the other side, at right angles to `u`.
        v: DVec3,
    },
}

/// A light with colour, intensity and shadow softness.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct Light {
    /// Directional or point.
    pub source: LightSource,
    /// Linear RGB colour, each component at least 0.
    #[serde(default = "white")]
    pub color: DVec3,
    /// Brightness multiplier, at least 0.
    #[serde(default = "one")]
    pub intensity: f64,
    /// Soft-shadow penumbra width: 0 gives hard shadows, larger values give
    /// wider penumbrae (0.05 is a good start).
    #[serde(default = "default_softness")]
    pub softness: f64,
}

/// A light's colour when a scene file leaves it out.
fn white() -> DVec3 {
    DVec3::ONE
}

/// A light's intensity when a scene file leaves it out.
fn one() -> f64 {
    1.0
}

/// A light's softness when a scene file leaves it out, as the builders set.
fn default_softness() -> f64 {
    Light::DEFAULT_SOFTNESS
}

impl Light {
    /// The penumbra width the builders give a light.
    pub const DEFAULT_SOFTNESS: f64 = 0.05;

    /// A white directional light shining from `direction`.
    #[must_use]
    pub fn directional(direction: impl Into<DVec3>) -> Self {
        Light {
            source: LightSource::Directional {
                direction: direction.into(),
            },
            color: DVec3::ONE,
            intensity: 1.0,
            softness: Light::DEFAULT_SOFTNESS,
        }
    }

    /// A white point light at `position`.
    #[must_use]
    pub fn point(position: impl Into<DVec3>) -> Self {
        Light {
            source: LightSource::Point {
                position: position.into(),
            },
            color: DVec3::ONE,
            intensity: 1.0,
            softness: Light::DEFAULT_SOFTNESS,
        }
    }

    /// A white ball of light of `radius` at `position`
    /// ([`LightSource::Sphere`]).
    #[must_use]
    pub fn sphere(position: impl Into<DVec3>, radius: f64) -> Self {
        Light {
            source: LightSource::Sphere {
                position: position.into(),
                radius,
            },
            color: DVec3::ONE,
            intensity: 1.0,
            softness: Light::DEFAULT_SOFTNESS,
        }
    }

    /// A white rectangle of light centred at `position`, spanning `±u` and
    /// `±v` from it and shining along `u × v` ([`LightSource::Rect`]).
    #[must_use]
    pub fn rect(position: impl Into<DVec3>, u: impl Into<DVec3>, v: impl Into<DVec3>) -> Self {
        Light {
            source: LightSource::Rect {
                position: position.into(),
                u: u.into(),
                v: v.into(),
            },
            color: DVec3::ONE,
            intensity: 1.0,
            softness: Light::DEFAULT_SOFTNESS,
        }
    }

    /// Sets the colour.
    #[must_use]
    pub fn color(mut self, rgb: impl Into<DVec3>) -> Self {
        self.color = rgb.into();
        self
    }

    /// Sets the intensity.
    #[must_use]
    pub fn intensity(mut self, intensity: f64) -> Self {
        self.intensity = intensity;
        self
    }

    /// Sets the penumbra width (0: hard shadows).
    #[must_use]
    pub fn softness(mut self, softness: f64) -> Self {
        self.softness = softness;
        self
    }

    /// Checks the light, which is `light[index]` in error messages: finite
    /// values, a direction that is not zero (its length does not matter:
    /// it is normalised robustly), colour, intensity and softness at least
    /// 0, and every value but the direction within the `F64` limits
    /// ([`Precision::limits`](crate::quality::Precision::limits)).
    pub(crate) fn validate(&self, index: usize) -> Result<()> {
        let node = format!("light[{index}]");
        let vector = |name: &str, v: DVec3, nonzero: bool| -> Result<()> {
            if let Some(bad) = v.to_array().into_iter().find(|c| !c.is_finite()) {
                return Err(Error::NonFinite {
                    node: node.clone(),
                    param: name.into(),
                    value: bad,
                });
            }
            if nonzero && normalize(v).is_none() {
                return Err(Error::ZeroVector {
                    node: node.clone(),
                    param: name.into(),
                });
            }
            Ok(())
        };
        match self.source {
            LightSource::Directional { direction } => vector("direction", direction, true)?,
            LightSource::Point { position } => {
                vector("position", position, false)?;
                within(&node, "position", position, Magnitude::Coordinate)?;
            }
            LightSource::Sphere { position, radius } => {
                vector("position", position, false)?;
                within(&node, "position", position, Magnitude::Coordinate)?;
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(Error::OutOfRange {
                        node: node.clone(),
                        param: "radius".into(),
                        value: radius,
                        expected: "> 0".into(),
                    });
                }
                within_scalar(&node, "radius", radius, Magnitude::Size)?;
            }
            LightSource::Rect { position, u, v } => {
                vector("position", position, false)?;
                within(&node, "position", position, Magnitude::Coordinate)?;
                vector("u", u, true)?;
                vector("v", v, true)?;
                within(&node, "u", u, Magnitude::Size)?;
                within(&node, "v", v, Magnitude::Size)?;
                let cos = u.dot(v) / (u.length() * v.length());
                if cos.abs() >= 1e-6 {
                    return Err(Error::OutOfRange {
                        node: node.clone(),
                        param: "v".into(),
                        value: cos,
                        expected: "at right angles to u (its cosine with u is shown)".into(),
                    });
                }
            }
        }
        vector("color", self.color, false)?;
        let scalars = [
            ("color", self.color.min_element()),
            ("intensity", self.intensity),
            ("softness", self.softness),
        ];
        for (name, value) in scalars {
            if !(value >= 0.0 && value.is_finite()) {
                return Err(Error::OutOfRange {
                    node: node.clone(),
                    param: name.into(),
                    value,
                    expected: ">= 0".into(),
                });
            }
        }
        within(&node, "color", self.color, Magnitude::Size)?;
        within_scalar(&node, "intensity", self.intensity, Magnitude::Size)?;
        within_scalar(&node, "softness", self.softness, Magnitude::Size)
    }
}

/// A camera or light value against the `F64` limits, which every scene
/// value keeps.
fn within_scalar(node: &str, param: &str, value: f64, magnitude: Magnitude) -> Result<()> {
    match F64_LIMITS.crossed(value, magnitude) {
        None => Ok(()),
        Some(limit) => Err(Error::Precision {
            node: node.into(),
            param: param.into(),
            value,
            precision: F64_LIMITS.precision,
            limit,
        }),
    }
}

/// Each component of a camera or light vector against the `F64` limits.
fn within(node: &str, param: &str, v: DVec3, magnitude: Magnitude) -> Result<()> {
    for (value, axis) in v.to_array().into_iter().zip(["x", "y", "z"]) {
        within_scalar(node, &format!("{param}.{axis}"), value, magnitude)?;
    }
    Ok(())
}

/// Geometry, lights and a camera: everything needed to render a picture.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Scene {
    /// The geometry, or `None` for an empty scene (which does not validate).
    pub geometry: Option<Node>,
    /// The lights; an empty list renders with ambient light only.
    pub lights: Vec<Light>,
    /// The camera.
    pub camera: Camera,
    /// Light from every direction, an HDR image around the scene; `None`
    /// (the default) for the sky gradient of the effects.
    pub environment: Option<Environment>,
}

impl Scene {
    /// A scene with `geometry`, the default camera and a key light from the
    /// upper right with a dimmer fill light.
    #[must_use]
    pub fn new(geometry: impl Into<Node>) -> Self {
        Scene {
            geometry: Some(geometry.into()),
            ..Scene::empty()
        }
    }

    /// A scene with no geometry (add some with [`Scene::add`]), the default
    /// camera and the default lights.
    #[must_use]
    pub fn empty() -> Self {
        Scene {
            geometry: None,
            lights: vec![
                Light::directional(DVec3::new(0.6, 0.8, 0.4)).intensity(1.0),
                Light::directional(DVec3::new(-0.7, 0.3, -0.5))
                    .intensity(0.25)
                    .color(DVec3::new(0.7, 0.8, 1.0)),
            ],
            camera: Camera::default(),
            environment: None,
        }
    }

    /// Adds geometry (a union with what is already there).
    #[must_use]
    #[allow(clippy::should_implement_trait)] // A builder step, not arithmetic.
    pub fn add(mut self, node: impl Into<Node>) -> Self {
        let node = node.into();
        self.geometry = Some(match self.geometry.take() {
            Some(g) => g.union(node),
            None => node,
        });
        self
    }

    /// Replaces the camera.
    #[must_use]
    pub fn with_camera(mut self, camera: Camera) -> Self {
        self.camera = camera;
        self
    }

    /// Replaces the lights.
    #[must_use]
    pub fn with_lights(mut self, lights: impl IntoIterator<Item = Light>) -> Self {
        self.lights = lights.into_iter().collect();
        self
    }

    /// Sets the environment light, or removes it with `None`.
    #[must_use]
    pub fn with_environment(mut self, environment: impl Into<Option<Environment>>) -> Self {
        self.environment = environment.into();
        self
    }
}
