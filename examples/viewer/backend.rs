//! The renderer the viewer draws with: the OpenCL backend's, or with the
//! `wgpu` feature the wgpu backend's (`--backend wgpu`). Both draw the
//! same picture; this enum gives the viewer the calls it makes of either.

use super::*;

#[cfg(feature = "wgpu")]
use fractal_sdf::render::WgpuRenderer;
use fractal_sdf::render::render_stereo;

/// The backends the viewer can draw with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum BackendKind {
    OpenCl,
    Wgpu,
}

impl BackendKind {
    /// `opencl` or `wgpu`.
    pub(super) fn from_name(name: &str) -> Result<Self> {
        match name {
            "opencl" => Ok(BackendKind::OpenCl),
            "wgpu" => Ok(BackendKind::Wgpu),
            _ => Err(common::usage(format!(
                "--backend `{name}`: expected opencl or wgpu"
            ))),
        }
    }
}

/// A renderer of either backend.
pub(super) enum Backend {
    OpenCl(Box<Renderer>),
    #[cfg(feature = "wgpu")]
    Wgpu(Box<WgpuRenderer>),
}

/// Runs `$body` with `$r` bound to the renderer, whichever backend it is.
macro_rules! each {
    ($backend:expr, $r:ident => $body:expr) => {
        match $backend {
            Backend::OpenCl($r) => $body,
            #[cfg(feature = "wgpu")]
            Backend::Wgpu($r) => $body,
        }
    };
}

impl Backend {
    /// A renderer of `compiled` on `kind`'s backend (`device` chooses the
    /// OpenCL device).
    pub(super) fn new(
        kind: BackendKind,
        compiled: CompiledScene,
        options: &RenderOptions,
    ) -> Result<Self> {
        match kind {
            BackendKind::OpenCl => Ok(Backend::OpenCl(Box::new(Renderer::from_compiled(
                compiled, options,
            )?))),
            #[cfg(feature = "wgpu")]
            BackendKind::Wgpu => Ok(Backend::Wgpu(Box::new(WgpuRenderer::from_compiled(
                compiled, options,
            )?))),
            #[cfg(not(feature = "wgpu"))]
            BackendKind::Wgpu => Err(common::usage(
                "--backend wgpu needs the viewer built with the `wgpu` feature \
                 (--features viewer,wgpu)",
            )),
        }
    }

    /// The same backend's renderer of `compiled`.
    pub(super) fn another(&self, compiled: CompiledScene, options: &RenderOptions) -> Result<Self> {
        Backend::new(self.kind(), compiled, options)
    }

    pub(super) fn kind(&self) -> BackendKind {
        match self {
            Backend::OpenCl(_) => BackendKind::OpenCl,
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(_) => BackendKind::Wgpu,
        }
    }

    /// What it runs on, for the console.
    pub(super) fn label(&self) -> String {
        match self {
            Backend::OpenCl(r) => r.device().label(),
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(r) => format!("{} (wgpu)", r.adapter().name),
        }
    }

    /// How long its program or pipeline took to build (0 from a cache).
    pub(super) fn build_time(&self) -> Duration {
        match self {
            Backend::OpenCl(r) => r.build_info().build_time,
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(r) => r.pipeline_time(),
        }
    }

    /// Whether its program (pipeline) came from the cache, not the
    /// compiler.
    pub(super) fn cached(&self) -> bool {
        match self {
            Backend::OpenCl(r) => r.build_info().cached,
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(r) => r.builds() == 0,
        }
    }

    /// Sets the quality and effects where they changed; returns whether
    /// the program they need came from the cache.
    pub(super) fn set_options(&mut self, quality: Quality, effects: Effects) -> Result<bool> {
        match self {
            Backend::OpenCl(r) => {
                if r.options().quality != quality {
                    r.set_quality(quality)?;
                }
                if r.options().effects != effects {
                    r.set_effects(effects)?;
                }
                Ok(r.build_info().cached)
            }
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(r) => {
                let built = r.builds();
                if r.options().quality != quality {
                    r.set_quality(quality)?;
                }
                if r.options().effects != effects {
                    r.set_effects(effects)?;
                }
                Ok(r.builds() == built)
            }
        }
    }

    /// Whether `compiled` with `quality` and `effects` is the program it
    /// runs, with the same parameter slots (so a reload may keep it).
    pub(super) fn runs(
        &self,
        compiled: &CompiledScene,
        quality: Quality,
        effects: Effects,
    ) -> Result<bool> {
        let options = codegen::Options::default()
            .quality(quality)
            .effects(effects)
            .target(codegen::Target::Render);
        let source = match self {
            Backend::OpenCl(_) => codegen::emit(compiled, &options)?,
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(_) => codegen::emit_wgsl(compiled, &options)?,
        };
        let (own, scene) = each!(self, r => (r.source(), r.scene()));
        Ok(source == *own && same_slots(scene.params(), compiled.params()))
    }

    pub(super) fn options(&self) -> &RenderOptions {
        each!(self, r => r.options())
    }

    pub(super) fn camera(&self) -> &Camera {
        each!(self, r => r.camera())
    }

    pub(super) fn set_camera(&mut self, camera: Camera) -> Result<()> {
        each!(self, r => r.set_camera(camera))
    }

    pub(super) fn param(&self, name: &str) -> Option<f64> {
        each!(self, r => r.param(name))
    }

    pub(super) fn set_param(&mut self, name: &str, value: f64) -> Result<()> {
        each!(self, r => r.set_param(name, value))
    }

    pub(super) fn set_lights(&mut self, lights: &[Light]) -> Result<()> {
        each!(self, r => r.set_lights(lights.iter().copied()))
    }

    pub(super) fn progressive_passes(&self) -> u32 {
        each!(self, r => r.progressive_passes())
    }

    pub(super) fn render(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        each!(self, r => r.render(width, height))
    }

    pub(super) fn render_progressive(&mut self, width: u32, height: u32) -> Result<RgbaImage> {
        each!(self, r => r.render_progressive(width, height))
    }

    pub(super) fn render_stereo(
        &mut self,
        width: u32,
        height: u32,
        stereo: &Stereo,
    ) -> Result<RgbaImage> {
        each!(self, r => render_stereo(r.as_mut(), width, height, stereo))
    }

    /// How long the last frame took.
    pub(super) fn last_frame_time(&self) -> Duration {
        match self {
            Backend::OpenCl(r) => r.last_timing().map_or(Duration::ZERO, |t| t.total),
            #[cfg(feature = "wgpu")]
            Backend::Wgpu(r) => r.last_timing().unwrap_or(Duration::ZERO),
        }
    }
}
