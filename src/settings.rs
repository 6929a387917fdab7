//! User settings shared by the `fractal-sdf` command and the viewer: the
//! default quality preset, image size and device, and the viewer's mouse
//! sensitivity and key bindings, read from a TOML file in the user's
//! configuration directory.
//!
//! The file is `fractal-sdf/config.toml` in the configuration directory
//! (`$XDG_CONFIG_HOME` or `~/.config` on Linux, `~/Library/Application
//! Support` on macOS, `%APPDATA%` on Windows), or the file the
//! `FRACTAL_SDF_CONFIG` environment variable names. Every setting may be
//! left out; a missing file means every default. Command-line flags
//! override the file.
//!
//! ```toml
//! preset = "preview"      # draft, preview, production or reference
//! size = "800x600"        # images and the viewer's window
//! device = "pthread"      # a substring of an OpenCL device's name
//! backend = "opencl"      # or "wgpu": the command's `render` and `bench --backend`
//!
//! [viewer]
//! mouse_sensitivity = 0.004   # radians per pixel
//!
//! [viewer.keys]           # action = key; see `view::Action::name`
//! toggle_glow = "l"
//! screenshot = "p"
//! ```
//!
//! ```
//! use fractal_sdf::settings::Settings;
//! let s = Settings::parse("preset = \"draft\"\n[viewer]\nmouse_sensitivity = 0.01")?;
//! assert_eq!(s.preset, Some(fractal_sdf::quality::Preset::Draft));
//! assert_eq!(s.viewer.mouse_sensitivity, Some(0.01));
//! assert!(Settings::parse("presett = 1").is_err());
//! use fractal_sdf::settings::Backend;
//! assert_eq!(Settings::parse("backend = \"wgpu\"")?.backend, Some(Backend::Wgpu));
//! assert!(Settings::parse("backend = \"metal\"").is_err());
//! # Ok::<(), fractal_sdf::Error>(())
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::quality::Preset;

/// The environment variable that names the settings file instead of the
/// one in the configuration directory.
pub const CONFIG_ENV: &str = "FRACTAL_SDF_CONFIG";

/// The settings file's contents; `None` is "not set" (the program's
/// default applies).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct Settings {
    /// The quality preset, by name in the file (`"preview"`).
    #[serde(default, with = "preset_name", skip_serializing_if = "Option::is_none")]
    pub preset: Option<Preset>,
    /// Image and window size, `"WIDTHxHEIGHT"` in the file.
    #[serde(default, with = "size_text", skip_serializing_if = "Option::is_none")]
    pub size: Option<(u32, u32)>,
    /// A substring of the OpenCL device's name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device: Option<String>,
    /// The backend the command's `render` and `bench` use (`"opencl"` or
    /// `"wgpu"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backend: Option<Backend>,
    /// The viewer's settings.
    #[serde(default)]
    pub viewer: ViewerSettings,
}

/// A backend that renders: the OpenCL executor
/// ([`Renderer`](crate::render::Renderer)) or the wgpu one
/// ([`WgpuRenderer`](crate::render::WgpuRenderer), feature `wgpu`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum Backend {
    /// OpenCL C on an OpenCL device.
    #[default]
    OpenCl,
    /// WGSL through wgpu.
    Wgpu,
}

impl Backend {
    /// Every backend.
    pub const ALL: [Backend; 2] = [Backend::OpenCl, Backend::Wgpu];

    /// Its name in settings files and on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Backend::OpenCl => "opencl",
            Backend::Wgpu => "wgpu",
        }
    }
}

/// The interactive viewer's settings.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct ViewerSettings {
    /// Radians of turn per pixel of mouse motion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mouse_sensitivity: Option<f64>,
    /// Key bindings that replace the defaults: an action's name to a key's
    /// name (`toggle_glow = "l"`). The viewer checks both names.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub keys: BTreeMap<String, String>,
}

impl Settings {
    /// The settings file's path: `$FRACTAL_SDF_CONFIG`, or
    /// `fractal-sdf/config.toml` in the user's configuration directory
    /// (`None` where the platform has none).
    #[must_use]
    pub fn path() -> Option<PathBuf> {
        match std::env::var_os(CONFIG_ENV) {
            Some(path) if !path.is_empty() => Some(PathBuf::from(path)),
            _ => dirs::config_dir().map(|dir| dir.join("fractal-sdf").join("config.toml")),
        }
    }

    /// The settings from [`Settings::path`]; every default where there is
    /// no such file.
    ///
    /// # Errors
    /// As [`Settings::load_from`].
    pub fn load() -> Result<Settings> {
        match Self::path() {
            Some(path) if path.exists() => Self::load_from(&path),
            _ => Ok(Settings::default()),
        }
    }

    /// The settings in the file at `path`.
    ///
    /// # Errors
    /// [`Error::Io`] if it cannot be read; [`Error::Invalid`] naming the
    /// file, line and column of a syntax error, an unknown setting or a bad
    /// value.
    pub fn load_from(path: &Path) -> Result<Settings> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| Error::io(path, "cannot read the settings file", source))?;
        parse(&text, &path.display().to_string())
    }

    /// The settings in `text`, TOML as in the module documentation.
    ///
    /// # Errors
    /// As [`Settings::load_from`], the file named `<settings>`.
    pub fn parse(text: &str) -> Result<Settings> {
        parse(text, "<settings>")
    }

    /// The settings as the file's TOML.
    ///
    /// # Errors
    /// None in practice (every value has a TOML form).
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Invalid {
            what: "settings",
            reason: e.to_string(),
        })
    }
}

fn parse(text: &str, file: &str) -> Result<Settings> {
    toml::from_str(text).map_err(|e| {
        let place = e
            .span()
            .map(|span| {
                let before = &text[..span.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
                format!("{file}:{line}:{column}")
            })
            .unwrap_or_else(|| file.to_string());
        Error::Invalid {
            what: "settings file",
            reason: format!("{place}: {}", e.message()),
        }
    })
}

/// `"WIDTHxHEIGHT"`, each side at least 1.
///
/// # Errors
/// [`Error::Invalid`] naming the text.
pub fn parse_size(text: &str) -> Result<(u32, u32)> {
    text.split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .filter(|&(w, h)| w > 0 && h > 0)
        .ok_or_else(|| Error::Invalid {
            what: "size",
            reason: format!("`{text}` is not a size like 640x480"),
        })
}

/// A preset by name, or an error listing the names.
///
/// # Errors
/// [`Error::Invalid`] naming the text and the presets.
pub fn parse_preset(text: &str) -> Result<Preset> {
    Preset::from_name(text).ok_or_else(|| {
        let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
        Error::Invalid {
            what: "quality preset",
            reason: format!("unknown preset `{text}` (one of: {})", names.join(", ")),
        }
    })
}

mod preset_name {
    use serde::{Deserialize, Deserializer, Serializer, de};

    use crate::quality::Preset;

    #[allow(clippy::ref_option)] // serde's `with` passes `&Option<T>`.
    pub fn serialize<S: Serializer>(p: &Option<Preset>, s: S) -> Result<S::Ok, S::Error> {
        match p {
            Some(p) => s.serialize_str(p.name()),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Preset>, D::Error> {
        let name = String::deserialize(d)?;
        super::parse_preset(&name)
            .map(Some)
            .map_err(|e| de::Error::custom(e.to_string()))
    }
}

mod size_text {
    use serde::{Deserialize, Deserializer, Serializer, de};

    #[allow(clippy::ref_option)] // serde's `with` passes `&Option<T>`.
    pub fn serialize<S: Serializer>(size: &Option<(u32, u32)>, s: S) -> Result<S::Ok, S::Error> {
        match size {
            Some((w, h)) => s.serialize_str(&format!("{w}x{h}")),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<(u32, u32)>, D::Error> {
        let text = String::deserialize(d)?;
        super::parse_size(&text)
            .map(Some)
            .map_err(|e| de::Error::custom(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_round_trips() {
        let mut s = Settings {
            preset: Some(Preset::Reference),
            size: Some((320, 200)),
            device: Some("pthread".into()),
            ..Settings::default()
        };
        s.viewer.mouse_sensitivity = Some(0.002);
        s.viewer.keys.insert("toggle_glow".into(), "l".into());
        let text = s.to_toml().unwrap();
        assert_eq!(Settings::parse(&text).unwrap(), s, "{text}");
    }

    #[test]
    fn bad_settings_name_the_line_and_column() {
        let e = Settings::parse("preset = \"draft\"\nsize = \"0x3\"\n").unwrap_err();
        assert!(e.to_string().contains("<settings>:2:8"), "{e}");
        assert!(e.to_string().contains("not a size"), "{e}");
        let e = Settings::parse("[viewer]\nmouse = 1\n").unwrap_err();
        assert!(e.to_string().contains("<settings>:2:1"), "{e}");
    }
}
