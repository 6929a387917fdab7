//! What the viewer draws and how ([`ViewSettings`]), changed by actions.

use glam::dvec3;

use super::bindings::Action;
use crate::quality::{Effects, Glow, Preset, Quality};
use crate::scene::StereoLayout;

/// The quality preset and effect switches of an interactive view.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ViewSettings {
    /// The quality preset.
    pub preset: Preset,
    /// A quality that is no preset (a scene file's), used instead of
    /// `preset` until a quality action picks a preset.
    pub custom_quality: Option<Quality>,
    /// Ambient occlusion on (the draft preset has no AO samples, so it
    /// shows none either way).
    pub ambient_occlusion: bool,
    /// Shadows on (none in the draft preset).
    pub shadows: bool,
    /// Glow on.
    pub glow: bool,
    /// The glow used when it is on.
    pub glow_style: Glow,
    /// Everything else about the effects (background, fog, gamma).
    pub base: Effects,
    /// The stereo layout, or `None` for one eye.
    pub stereo: Option<StereoLayout>,
}

impl Default for ViewSettings {
    /// Preview quality, AO and shadows on, a soft blue glow off.
    fn default() -> Self {
        ViewSettings {
            preset: Preset::Preview,
            custom_quality: None,
            ambient_occlusion: true,
            shadows: true,
            glow: false,
            glow_style: Glow {
                color: dvec3(0.6, 0.75, 1.0),
                strength: 0.8,
            },
            base: Effects::default(),
            stereo: None,
        }
    }
}

impl ViewSettings {
    /// The quality to render with: the custom one if set, else the
    /// preset's.
    #[must_use]
    pub fn quality(&self) -> Quality {
        self.custom_quality.unwrap_or_else(|| self.preset.quality())
    }

    /// Renders with `quality` from now on: its preset if it is one, else as
    /// [`ViewSettings::custom_quality`].
    pub fn take_quality(&mut self, quality: Quality) {
        match Preset::ALL.into_iter().find(|p| p.quality() == quality) {
            Some(preset) => {
                self.preset = preset;
                self.custom_quality = None;
            }
            None => self.custom_quality = Some(quality),
        }
    }

    /// Renders with `effects` from now on: its switches become the
    /// switches, its glow (if any) the glow style, and the rest the base.
    pub fn take_effects(&mut self, effects: Effects) {
        self.ambient_occlusion = effects.ambient_occlusion;
        self.shadows = effects.shadows;
        self.glow = effects.glow.is_some();
        if let Some(glow) = effects.glow {
            self.glow_style = glow;
        }
        self.base = effects;
    }

    /// The effects to render with.
    #[must_use]
    pub fn effects(&self) -> Effects {
        Effects {
            ambient_occlusion: self.ambient_occlusion,
            shadows: self.shadows,
            glow: self.glow.then_some(self.glow_style),
            ..self.base
        }
    }

    /// Applies an action; returns whether the settings changed (a new
    /// quality or new effects mean a new program; stereo does not).
    pub fn apply(&mut self, action: Action) -> bool {
        let before = *self;
        match action {
            Action::ToggleAmbientOcclusion => self.ambient_occlusion ^= true,
            Action::ToggleShadows => self.shadows ^= true,
            Action::ToggleGlow => self.glow ^= true,
            Action::CycleStereo => {
                let all = StereoLayout::ALL;
                self.stereo = match self.stereo {
                    None => Some(all[0]),
                    Some(layout) => {
                        let i = all.iter().position(|&l| l == layout).expect("a layout");
                        all.get(i + 1).copied()
                    }
                };
            }
            Action::Quality(p) => {
                self.preset = p;
                self.custom_quality = None;
            }
            _ => {}
        }
        *self != before
    }

    /// A short description, such as `preview, AO, shadows, glow,
    /// anaglyph` (`custom` for a custom quality).
    #[must_use]
    pub fn summary(&self) -> String {
        let quality = if self.custom_quality.is_some() {
            "custom"
        } else {
            self.preset.name()
        };
        let mut parts = vec![quality];
        for (on, name) in [
            (self.ambient_occlusion, "AO"),
            (self.shadows, "shadows"),
            (self.glow, "glow"),
        ] {
            if on {
                parts.push(name);
            }
        }
        parts.extend(self.stereo.map(StereoLayout::name));
        parts.join(", ")
    }
}
