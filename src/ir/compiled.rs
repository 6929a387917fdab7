//! The compiled scene: what [`Scene::compile`] hands to every later stage.

use super::{Ir, ParamLayout, ParamValues};
use crate::error::{Error, Result};
use crate::scene::{Camera, Environment, Light, Scene};

/// A scene validated and lowered once: the geometry's [`Ir`] with its
/// parameter layout (every rule, including those relating two
/// parameters), the camera and the lights.
///
/// Every later stage takes it: [`codegen::emit`](crate::codegen::emit),
/// [`cpu::Evaluator::from_compiled`](crate::cpu::Evaluator::from_compiled)
/// and, with `opencl`, the `Renderer` and `PointEvaluator`. None of them
/// validates or lowers again, and moving the camera or changing the
/// lights never touches code generation.
///
/// ```
/// use fractal_sdf::prelude::*;
///
/// let scene = Scene::new(round_box(dvec3(0.5, 0.5, 0.5), param("r", 0.1)));
/// let compiled = scene.compile()?;
/// let mut values = compiled.default_values();
/// // A dynamic value keeps every rule a baked one would:
/// let err = values.set("r", 0.9).unwrap_err();
/// assert_eq!(
///     err.to_string(),
///     "round_box: parameter `radius` must be <= the smallest half extent (0.5), got 0.9"
/// );
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CompiledScene {
    ir: Ir,
    camera: Camera,
    lights: Vec<Light>,
    environment: Option<Environment>,
}

impl CompiledScene {
    /// The lowered geometry.
    #[must_use]
    pub fn ir(&self) -> &Ir {
        &self.ir
    }

    /// The parameter buffer's layout.
    #[must_use]
    pub fn params(&self) -> &ParamLayout {
        self.ir.layout()
    }

    /// The dynamic parameters at their defaults.
    #[must_use]
    pub fn default_values(&self) -> ParamValues {
        self.ir.default_values()
    }

    /// The camera.
    #[must_use]
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The lights.
    #[must_use]
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Replaces the camera, after checking it.
    ///
    /// # Errors
    /// [`Error::Camera`] if the camera is degenerate.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        camera.validate()?;
        self.camera = camera;
        Ok(())
    }

    /// Replaces the lights, after checking them.
    ///
    /// # Errors
    /// The first invalid light, as [`Scene::compile`] reports it.
    pub fn set_lights(&mut self, lights: impl IntoIterator<Item = Light>) -> Result<()> {
        let lights: Vec<Light> = lights.into_iter().collect();
        validate_lights(&lights)?;
        self.lights = lights;
        Ok(())
    }

    /// The environment light.
    #[must_use]
    pub fn environment(&self) -> Option<&Environment> {
        self.environment.as_ref()
    }

    /// Replaces the environment light, or removes it with `None`.
    ///
    /// # Errors
    /// [`Error::Environment`] for one that does not validate.
    pub fn set_environment(&mut self, environment: Option<Environment>) -> Result<()> {
        if let Some(e) = &environment {
            e.validate()?;
        }
        self.environment = environment;
        Ok(())
    }
}

impl Scene {
    /// Validates and lowers the scene, once, into the value every later
    /// stage takes.
    ///
    /// # Errors
    /// The first problem found, as a typed [`Error`] naming the node path
    /// and the parameter: [`Error::EmptyScene`], geometry errors, then the
    /// camera's, then the lights'.
    pub fn compile(&self) -> Result<CompiledScene> {
        let geometry = self.geometry.as_ref().ok_or(Error::EmptyScene)?;
        let ir = Ir::lower(geometry)?;
        self.camera.validate()?;
        validate_lights(&self.lights)?;
        if let Some(environment) = &self.environment {
            environment.validate()?;
        }
        Ok(CompiledScene {
            ir,
            camera: self.camera,
            lights: self.lights.clone(),
            environment: self.environment.clone(),
        })
    }

    /// Checks every value in the scene: geometry parameters, camera and
    /// lights ([`Scene::compile`], keeping nothing).
    ///
    /// # Errors
    /// As [`Scene::compile`].
    pub fn validate(&self) -> Result<()> {
        self.compile().map(drop)
    }
}

/// The most lights a scene holds: their count is an `int` kernel argument.
pub const MAX_LIGHTS: usize = i32::MAX as usize;

/// The one check of a scene's lights: each light's values, and their count.
fn validate_lights(lights: &[Light]) -> Result<()> {
    if lights.len() > MAX_LIGHTS {
        return Err(Error::TooManyLights {
            count: lights.len(),
            max: MAX_LIGHTS,
        });
    }
    lights
        .iter()
        .enumerate()
        .try_for_each(|(i, light)| light.validate(i))
}
