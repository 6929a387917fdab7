//! Building OpenCL programs, with a process-wide cache.
//!
//! Compiled programs are kept, keyed by (device, build options, source): a
//! second renderer of the same scene and settings, or switching back to
//! earlier settings, does not compile again. The cache holds the
//! [`PROGRAM_CACHE_CAPACITY`] most recently used programs; a renderer keeps
//! its own program alive whether or not the cache still holds it.
//! Contexts are shared per device because a program belongs to one.

use std::collections::HashMap;
use std::ffi::CString;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};
use std::time::{Duration, Instant};

use ocl::core::{ClDeviceIdPtr, ProgramBuildInfo, ProgramBuildInfoResult};
use ocl::{Context, Program};

use super::cache::Lru;
use super::device::{DeviceInfo, Selected, opencl};
use crate::codegen::KernelSource;
use crate::error::{Error, Result};
use crate::quality::Precision;

/// How a renderer's program was obtained.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BuildInfo {
    /// The device it was built for, as `"platform / device"`.
    pub device: String,
    /// The compiler options.
    pub options: String,
    /// How long the OpenCL compiler took (when it first ran, for a cached
    /// program).
    pub build_time: Duration,
    /// Whether the program came from the process-wide cache.
    pub cached: bool,
    /// The source's hash ([`KernelSource::hash`]), to tell programs apart
    /// in logs.
    pub source_hash: u64,
}

/// Programs compiled by the OpenCL compiler in this process so far (cache
/// hits do not count).
#[must_use]
pub fn program_builds() -> u64 {
    BUILDS.load(Ordering::Relaxed)
}

static BUILDS: AtomicU64 = AtomicU64::new(0);

type DeviceKey = usize;

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct ProgramKey {
    device: DeviceKey,
    options: String,
    source: String,
}

#[derive(Debug, Clone)]
struct Built {
    program: Program,
    build_time: Duration,
}

type Slot = Arc<Mutex<Option<Built>>>;

fn contexts() -> &'static Mutex<HashMap<DeviceKey, Context>> {
    static CONTEXTS: OnceLock<Mutex<HashMap<DeviceKey, Context>>> = OnceLock::new();
    CONTEXTS.get_or_init(Mutex::default)
}

/// How many compiled programs the process-wide cache keeps: the most
/// recently used ones. A program takes about 1.5 MB of host memory on
/// PoCL, so the cache stays near 100 MB however many scenes a process
/// renders (unbounded, 400 distinct scenes grew a process from 118 MB to
/// 684 MB; with this bound its size stays flat after the 64th).
pub const PROGRAM_CACHE_CAPACITY: usize = 64;

fn programs() -> &'static Mutex<Lru<ProgramKey, Slot>> {
    static PROGRAMS: OnceLock<Mutex<Lru<ProgramKey, Slot>>> = OnceLock::new();
    PROGRAMS.get_or_init(|| Mutex::new(Lru::new(PROGRAM_CACHE_CAPACITY)))
}

fn device_key(selected: &Selected) -> DeviceKey {
    selected.device.as_core().as_ptr() as usize
}

/// The shared context of a device.
pub(crate) fn context(selected: &Selected) -> Result<Context> {
    let mut map = contexts().lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(c) = map.get(&device_key(selected)) {
        return Ok(c.clone());
    }
    let context = Context::builder()
        .platform(selected.platform)
        .devices(selected.device)
        .build()
        .map_err(opencl)?;
    map.insert(device_key(selected), context.clone());
    Ok(context)
}

/// Compiler options for a device: OpenCL C 1.2 where the device has it.
pub(crate) fn build_options(info: &DeviceInfo) -> String {
    if info.has_opencl_c_1_2() {
        "-cl-std=CL1.2".into()
    } else {
        String::new()
    }
}

/// The program for `source` on the selected device, from the cache or
/// freshly compiled. Returns it with its build information and whether the
/// compiler ran.
pub(crate) fn build(
    selected: &Selected,
    context: &Context,
    source: &KernelSource,
) -> Result<(Program, BuildInfo, bool)> {
    if source.precision == Precision::F64 {
        selected.info.require_fp64()?;
    }
    let options = build_options(&selected.info);
    let key = ProgramKey {
        device: device_key(selected),
        options: options.clone(),
        source: source.source.clone(),
    };
    let slot = programs()
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .get_or_insert_with(key, Slot::default)
        .clone();
    // Only one thread compiles a given program; others wait for it.
    let mut slot = slot.lock().unwrap_or_else(PoisonError::into_inner);
    let compiled_now = slot.is_none();
    let built = match &*slot {
        Some(b) => b.clone(),
        None => {
            let b = compile(selected, context, &source.source, &options)?;
            BUILDS.fetch_add(1, Ordering::Relaxed);
            *slot = Some(b.clone());
            b
        }
    };
    let info = BuildInfo {
        device: selected.info.label(),
        options,
        build_time: built.build_time,
        cached: !compiled_now,
        source_hash: source.hash,
    };
    Ok((built.program, info, compiled_now))
}

fn compile(selected: &Selected, context: &Context, source: &str, options: &str) -> Result<Built> {
    let failed = |log: String| Error::Build {
        device: selected.info.label(),
        log,
        kernel_source: source.to_string(),
    };
    let text = CString::new(source).map_err(|e| failed(format!("the source {e}")))?;
    let opts = CString::new(options).map_err(|e| failed(format!("the options {e}")))?;
    let program = ocl::core::create_program_with_source(context, &[text])
        .map_err(|e| failed(e.to_string()))?;
    let start = Instant::now();
    let result = ocl::core::build_program(&program, Some(&[selected.device]), &opts, None, None);
    let build_time = start.elapsed();
    if let Err(e) = result {
        let log = match ocl::core::get_program_build_info(
            &program,
            selected.device,
            ProgramBuildInfo::BuildLog,
        ) {
            Ok(ProgramBuildInfoResult::BuildLog(log)) if !log.trim().is_empty() => log,
            _ => e.to_string(),
        };
        return Err(failed(log.trim_end_matches('\0').trim_end().to_string()));
    }
    Ok(Built {
        program: Program::from(program),
        build_time,
    })
}
