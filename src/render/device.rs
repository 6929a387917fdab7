//! Finding OpenCL devices and choosing one.

use std::sync::{Mutex, PoisonError};

use ocl::core::{DeviceInfo as Query, DeviceInfoResult, DeviceType, PlatformInfo};
use ocl::{Device, Platform};

use crate::error::{Error, Result};

/// The environment variable that picks a device when the program does not:
/// a case-insensitive substring of `"platform / device"`, as listed by
/// [`devices`] (for example `FRACTAL_SDF_DEVICE=nvidia`, or `=portable` for
/// PoCL, the "Portable Computing Language").
pub const DEVICE_ENV: &str = "FRACTAL_SDF_DEVICE";

/// What kind of processor a device is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum DeviceKind {
    /// A graphics processor.
    Gpu,
    /// A CPU (for example through PoCL).
    Cpu,
    /// An accelerator card.
    Accelerator,
    /// Anything else.
    Other,
}

/// One OpenCL device, as reported by its driver.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct DeviceInfo {
    /// The platform (driver family), such as `Portable Computing Language`.
    pub platform: String,
    /// The device's name.
    pub name: String,
    /// The device's vendor.
    pub vendor: String,
    /// GPU, CPU, ...
    pub kind: DeviceKind,
    /// The device's OpenCL version string, such as `OpenCL 3.0 PoCL 5.0`.
    pub opencl_version: String,
    /// The OpenCL C language version, such as `OpenCL C 1.2 PoCL`.
    pub opencl_c_version: String,
    /// The driver's version.
    pub driver_version: String,
    /// Whether the device supports double precision (`cl_khr_fp64`).
    pub fp64: bool,
    /// Parallel compute units.
    pub compute_units: u32,
    /// The largest work group the device runs.
    pub max_work_group_size: usize,
    /// Global memory in bytes.
    pub global_memory: u64,
    /// The largest single buffer in bytes.
    pub max_allocation: u64,
}

impl DeviceInfo {
    /// `"platform / device"`, the text [`DEVICE_ENV`] is matched against.
    #[must_use]
    pub fn label(&self) -> String {
        format!("{} / {}", self.platform, self.name)
    }

    /// Whether the device compiles OpenCL C 1.2 or later.
    pub(crate) fn has_opencl_c_1_2(&self) -> bool {
        parse_version(&self.opencl_c_version).is_some_and(|v| v >= (1, 2))
    }

    /// [`Error::Fp64Unsupported`] unless the device has `cl_khr_fp64`.
    pub(crate) fn require_fp64(&self) -> Result<()> {
        if self.fp64 {
            Ok(())
        } else {
            Err(Error::Fp64Unsupported {
                device: self.label(),
            })
        }
    }
}

/// `(major, minor)` from the first `N.M` in an OpenCL version string.
fn parse_version(text: &str) -> Option<(u32, u32)> {
    text.split_whitespace().find_map(|word| {
        let (major, minor) = word.split_once('.')?;
        Some((major.parse().ok()?, minor.parse().ok()?))
    })
}

/// Which device to render on. Empty fields match everything; an empty
/// selector means "automatic": the [`DEVICE_ENV`] variable if set, else the
/// first GPU, else the first device.
///
/// Names match as case-insensitive substrings; among matches a GPU is
/// preferred.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct DeviceSelector {
    /// A substring of the platform's name, such as `"nvidia"` or
    /// `"portable"` (PoCL).
    pub platform: Option<String>,
    /// A substring of the device's name.
    pub device: Option<String>,
    /// The device's position in [`devices`] (from 0), which tells apart
    /// devices of the same name (several identical GPUs). It must also
    /// match the names given.
    pub index: Option<usize>,
}

impl DeviceSelector {
    /// Automatic selection (see [`DeviceSelector`]).
    #[must_use]
    pub fn auto() -> Self {
        Self::default()
    }

    /// The first device whose name contains `name`.
    #[must_use]
    pub fn device(name: impl Into<String>) -> Self {
        DeviceSelector {
            device: Some(name.into()),
            ..Self::default()
        }
    }

    /// The device `info` describes: its platform's and its own name (the
    /// first of two devices with the same names on one platform; see
    /// [`DeviceSelector::at`] to tell them apart).
    #[must_use]
    pub fn exactly(info: &DeviceInfo) -> Self {
        DeviceSelector {
            platform: Some(info.platform.clone()),
            device: Some(info.name.clone()),
            index: None,
        }
    }

    /// The device at `index` in [`devices`]' list.
    #[must_use]
    pub fn at(index: usize) -> Self {
        DeviceSelector {
            index: Some(index),
            ..Self::default()
        }
    }

    /// The first device of the platform whose name contains `name`.
    #[must_use]
    pub fn platform(name: impl Into<String>) -> Self {
        DeviceSelector {
            platform: Some(name.into()),
            ..Self::default()
        }
    }

    /// The device this selector picks, as a renderer built with it would
    /// (the [`DEVICE_ENV`] variable applies to automatic selection).
    ///
    /// # Errors
    /// [`Error::NoPlatform`], [`Error::NoDevice`].
    pub fn resolve(&self) -> Result<DeviceInfo> {
        select(self).map(|s| s.info)
    }

    fn is_auto(&self) -> bool {
        self.platform.is_none() && self.device.is_none() && self.index.is_none()
    }

    fn describe(&self) -> String {
        let part = |what: &str, v: &Option<String>| v.as_ref().map(|s| format!("{what} ~ `{s}`"));
        [
            part("platform", &self.platform),
            part("device", &self.device),
            self.index.map(|i| format!("device number {i}")),
        ]
        .into_iter()
        .flatten()
        .collect::<Vec<_>>()
        .join(", ")
    }
}

/// Every OpenCL device on every platform.
///
/// ```no_run
/// for d in fractal_sdf::render::devices()? {
///     println!("{} ({:?}, fp64: {})", d.label(), d.kind, d.fp64);
/// }
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
///
/// # Errors
/// [`Error::NoPlatform`] if no OpenCL platform is installed (the message
/// says how to install one), [`Error::OpenCl`] if a driver fails to answer.
pub fn devices() -> Result<Vec<DeviceInfo>> {
    Ok(enumerate()?.into_iter().map(|(info, _)| info).collect())
}

/// A chosen device with its OpenCL handles.
#[derive(Debug, Clone)]
pub(crate) struct Selected {
    pub info: DeviceInfo,
    pub platform: Platform,
    pub device: Device,
}

/// Chooses a device for `selector` (see [`DeviceSelector`]).
pub(crate) fn select(selector: &DeviceSelector) -> Result<Selected> {
    let all = enumerate()?;
    let infos: Vec<DeviceInfo> = all.iter().map(|(i, _)| i.clone()).collect();
    let env = std::env::var(DEVICE_ENV).ok();
    let index = choose(&infos, selector, env.as_deref())?;
    let (info, (platform, device)) = all.into_iter().nth(index).expect("index from choose");
    Ok(Selected {
        info,
        platform,
        device,
    })
}

/// The index in `devices` that `selector` (or else `env`, the value of
/// [`DEVICE_ENV`]) picks.
fn choose(devices: &[DeviceInfo], selector: &DeviceSelector, env: Option<&str>) -> Result<usize> {
    let contains = |hay: &str, needle: &str| hay.to_lowercase().contains(&needle.to_lowercase());
    let env = env.map(str::trim).filter(|e| !e.is_empty());
    let (matches, selection): (Vec<usize>, String) = if !selector.is_auto() {
        let m = (0..devices.len())
            .filter(|&i| {
                let d = &devices[i];
                selector.index.is_none_or(|at| at == i)
                    && selector
                        .platform
                        .as_ref()
                        .is_none_or(|p| contains(&d.platform, p))
                    && selector
                        .device
                        .as_ref()
                        .is_none_or(|n| contains(&d.name, n))
            })
            .collect();
        (m, selector.describe())
    } else if let Some(e) = env {
        let m = (0..devices.len())
            .filter(|&i| contains(&devices[i].label(), e))
            .collect();
        (m, format!("{DEVICE_ENV}=`{e}`"))
    } else {
        ((0..devices.len()).collect(), "any device".into())
    };
    let gpu = matches
        .iter()
        .copied()
        .find(|&i| devices[i].kind == DeviceKind::Gpu);
    gpu.or_else(|| matches.first().copied())
        .ok_or_else(|| Error::NoDevice {
            selection,
            available: if devices.is_empty() {
                "none".into()
            } else {
                devices
                    .iter()
                    .map(DeviceInfo::label)
                    .collect::<Vec<_>>()
                    .join("; ")
            },
        })
}

type Enumerated = Vec<(DeviceInfo, (Platform, Device))>;

/// Every device with its handles, listed once per process. Listing is
/// serialised: some drivers (PoCL among them) initialise lazily and crash
/// when two threads make their first calls at once.
fn enumerate() -> Result<Enumerated> {
    static LISTED: Mutex<Option<Enumerated>> = Mutex::new(None);
    let mut listed = LISTED.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(all) = &*listed {
        return Ok(all.clone());
    }
    let all = list_devices()?;
    *listed = Some(all.clone());
    Ok(all)
}

/// `Platform::list` panics when the loader finds no platform, so the list
/// comes from the core call, which returns an error instead.
fn list_devices() -> Result<Enumerated> {
    let ids = ocl::core::get_platform_ids().map_err(|e| Error::NoPlatform {
        detail: e.to_string().lines().next().unwrap_or_default().to_string(),
    })?;
    if ids.is_empty() {
        return Err(Error::NoPlatform {
            detail: "the OpenCL loader lists no platforms".into(),
        });
    }
    let mut out = Vec::new();
    for platform in Platform::list_from_core(ids) {
        let platform_name = platform
            .info(PlatformInfo::Name)
            .map(|n| n.to_string().trim().to_string())
            .map_err(opencl)?;
        // A platform with no devices answers with an error: skip it.
        let Ok(devices) = Device::list_all(platform) else {
            continue;
        };
        for device in devices {
            out.push((describe(&platform_name, &device)?, (platform, device)));
        }
    }
    Ok(out)
}

fn describe(platform: &str, device: &Device) -> Result<DeviceInfo> {
    let text = |q: Query| -> Result<String> {
        let bytes = device.info_raw(q as u32).map_err(opencl)?;
        let s = String::from_utf8_lossy(&bytes);
        Ok(s.trim_end_matches('\0').trim().to_string())
    };
    let info = |q: Query| device.info(q).map_err(opencl);
    let kind = match info(Query::Type)? {
        DeviceInfoResult::Type(t) if t.contains(DeviceType::GPU) => DeviceKind::Gpu,
        DeviceInfoResult::Type(t) if t.contains(DeviceType::CPU) => DeviceKind::Cpu,
        DeviceInfoResult::Type(t) if t.contains(DeviceType::ACCELERATOR) => DeviceKind::Accelerator,
        _ => DeviceKind::Other,
    };
    let compute_units = match info(Query::MaxComputeUnits)? {
        DeviceInfoResult::MaxComputeUnits(n) => n,
        _ => 0,
    };
    let global_memory = match info(Query::GlobalMemSize)? {
        DeviceInfoResult::GlobalMemSize(n) => n,
        _ => 0,
    };
    let max_allocation = match info(Query::MaxMemAllocSize)? {
        DeviceInfoResult::MaxMemAllocSize(n) => n,
        _ => 0,
    };
    let extensions = text(Query::Extensions)?;
    Ok(DeviceInfo {
        platform: platform.to_string(),
        name: text(Query::Name)?,
        vendor: text(Query::Vendor)?,
        kind,
        opencl_version: text(Query::Version)?,
        opencl_c_version: text(Query::OpenclCVersion)?,
        driver_version: text(Query::DriverVersion)?,
        fp64: extensions.split_whitespace().any(|e| e == "cl_khr_fp64"),
        compute_units,
        max_work_group_size: device.max_wg_size().map_err(opencl)?,
        global_memory,
        max_allocation,
    })
}

/// Any OpenCL failure as [`Error::OpenCl`].
pub(crate) fn opencl(e: impl std::fmt::Display) -> Error {
    Error::OpenCl(e.to_string())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn fake(platform: &str, name: &str, kind: DeviceKind) -> DeviceInfo {
        DeviceInfo {
            platform: platform.into(),
            name: name.into(),
            vendor: String::new(),
            kind,
            opencl_version: "OpenCL 3.0".into(),
            opencl_c_version: "OpenCL C 1.2 fake".into(),
            driver_version: "1".into(),
            fp64: false,
            compute_units: 1,
            max_work_group_size: 256,
            global_memory: 1 << 30,
            max_allocation: 1 << 28,
        }
    }

    fn list() -> Vec<DeviceInfo> {
        vec![
            fake(
                "Portable Computing Language",
                "pthread-cpu",
                DeviceKind::Cpu,
            ),
            fake("NVIDIA CUDA", "GeForce RTX", DeviceKind::Gpu),
            fake("Intel(R) OpenCL", "Intel CPU", DeviceKind::Cpu),
        ]
    }

    #[test]
    fn automatic_prefers_the_first_gpu() {
        assert_eq!(choose(&list(), &DeviceSelector::auto(), None).unwrap(), 1);
        let cpus = [list()[0].clone(), list()[2].clone()];
        assert_eq!(choose(&cpus, &DeviceSelector::auto(), None).unwrap(), 0);
    }

    #[test]
    fn env_matches_platform_slash_device_case_insensitively() {
        let auto = DeviceSelector::auto();
        assert_eq!(choose(&list(), &auto, Some("portable")).unwrap(), 0);
        assert_eq!(
            choose(&list(), &auto, Some("language / PTHREAD")).unwrap(),
            0
        );
        assert_eq!(choose(&list(), &auto, Some("intel")).unwrap(), 2);
        // Blank means unset.
        assert_eq!(choose(&list(), &auto, Some("  ")).unwrap(), 1);
    }

    #[test]
    fn an_explicit_selector_wins_over_the_environment() {
        let sel = DeviceSelector::platform("intel");
        assert_eq!(choose(&list(), &sel, Some("nvidia")).unwrap(), 2);
        let sel = DeviceSelector::device("cpu");
        assert_eq!(choose(&list(), &sel, None).unwrap(), 0);
    }

    #[test]
    fn no_match_lists_what_exists() {
        let err = choose(&list(), &DeviceSelector::device("radeon"), None).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, Error::NoDevice { .. }));
        assert!(
            text.contains("radeon") && text.contains("NVIDIA CUDA / GeForce RTX"),
            "{text}"
        );
        let err = choose(&list(), &DeviceSelector::auto(), Some("amd")).unwrap_err();
        assert!(
            err.to_string().contains("FRACTAL_SDF_DEVICE=`amd`"),
            "{err}"
        );
    }

    #[test]
    fn versions_and_fp64() {
        assert_eq!(parse_version("OpenCL C 1.2 pocl"), Some((1, 2)));
        assert_eq!(parse_version("OpenCL 3.0 CUDA"), Some((3, 0)));
        assert!(fake("p", "d", DeviceKind::Cpu).has_opencl_c_1_2());
        let err = fake("p", "d", DeviceKind::Cpu).require_fp64().unwrap_err();
        assert!(matches!(err, Error::Fp64Unsupported { .. }));
        assert!(err.to_string().contains("Precision::F32"));
    }
}
