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
#[non_exhaustive]
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

/// Compiler options for a device (OpenCL C 1.2 where the device has it)
/// and a program (relaxed math where it asks for it).
pub(crate) fn build_options(info: &DeviceInfo, fast_math: bool) -> String {
    let mut options = Vec::new();
    if info.has_opencl_c_1_2() {
        options.push("-cl-std=CL1.2");
    }
    if fast_math {
        options.push("-cl-unsafe-math-optimizations");
    }
    options.join(" ")
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
    let options = build_options(&selected.info, source.fast_math);
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
            let b = compile(selected, context, source, &options)?;
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

fn compile(
    selected: &Selected,
    context: &Context,
    kernel: &KernelSource,
    options: &str,
) -> Result<Built> {
    let source = kernel.source.as_str();
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
        let log = log.trim_end_matches('\0').trim_end().to_string();
        return Err(build_error(selected.info.label(), log, kernel));
    }
    Ok(Built {
        program: Program::from(program),
        build_time,
    })
}

/// The error for a failed build: [`Error::CustomShapeBuild`] when the log
/// has an error about a line of a custom shape's definition (the first
/// such error), [`Error::Build`] otherwise.
fn build_error(device: String, log: String, kernel: &KernelSource) -> Error {
    let custom = diagnostics(&log).into_iter().find_map(|d| {
        let (region, line) = kernel.custom_line(d.line)?;
        Some((region.shape.clone(), line, d))
    });
    let build = Error::Build {
        device,
        log,
        kernel_source: kernel.source.clone(),
    };
    match custom {
        Some((shape, line, d)) => Error::CustomShapeBuild {
            shape,
            line,
            column: d.column,
            text: kernel.line(d.line).unwrap_or_default().to_string(),
            message: d.message,
            build: Box::new(build),
        },
        None => build,
    }
}

/// An error message of a build log, with where in the program it points.
#[derive(Debug, PartialEq)]
struct Diagnostic {
    line: usize,
    column: usize,
    message: String,
}

/// The errors of a build log that say where they are, in order.
///
/// Compilers write a location as `FILE:LINE:COL` (the file a temporary
/// path, `<stdin>`, `<kernel>`, `<source>` or a number) with the severity
/// before it (PoCL: `error: FILE:L:C: message`) or after it (clang, NVIDIA,
/// AMD, Intel: `FILE:L:C: error: message`). The first `:LINE:COL` of a line
/// is taken: where a macro was expanded, PoCL adds the macro's own place
/// after it (`<Spelling=...>`). Warnings and notes are skipped.
fn diagnostics(log: &str) -> Vec<Diagnostic> {
    log.lines()
        .filter_map(|text| {
            let severity = ["error:", "warning:", "note:"]
                .iter()
                .filter_map(|s| text.find(s).map(|at| (at, *s)))
                .min()?;
            if severity.1 != "error:" {
                return None;
            }
            let (line, column, end) = location(text)?;
            let mut message = text[end..].trim_start();
            if message.starts_with("<Spelling=") {
                message = message.find('>').map_or("", |e| &message[e + 1..]);
            }
            let message = message.trim_start_matches([':', ' ']);
            let message = message
                .strip_prefix("fatal error:")
                .or_else(|| message.strip_prefix("error:"))
                .unwrap_or(message)
                .trim();
            Some(Diagnostic {
                line,
                column,
                message: message.to_string(),
            })
        })
        .collect()
}

/// The first `:LINE:COL` of `text`: the line, the column and where the
/// location ends.
fn location(text: &str) -> Option<(usize, usize, usize)> {
    let bytes = text.as_bytes();
    let number = |from: usize| {
        let len = bytes[from..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count();
        (len > 0).then(|| (text[from..from + len].parse::<usize>().ok(), from + len))
    };
    text.match_indices(':').find_map(|(at, _)| {
        let (line, after) = number(at + 1)?;
        if bytes.get(after) != Some(&b':') {
            return None;
        }
        let (column, end) = number(after + 1)?;
        Some((line?, column?, end))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codegen::CustomRegion;
    use glam::DVec3;

    fn program() -> KernelSource {
        let source: String = (1..=20).map(|i| format!("line {i}\n")).collect();
        KernelSource {
            source,
            language: crate::codegen::Language::OpenCl,
            precision: Precision::F32,
            hash: 0,
            fast_math: false,
            cone_tile: 0,
            brute: false,
            origin: DVec3::ZERO,
            kernel_start: 0,
            constants: Vec::new(),
            tables: crate::codegen::InstanceTables::default(),
            // Signature on line 9, body on lines 10 and 11, brace on 12.
            custom_regions: vec![CustomRegion {
                shape: "gyroid".into(),
                first_line: 10,
                lines: 2,
            }],
        }
    }

    #[test]
    fn locations_are_read_from_every_compilers_log_format() {
        for (log, line, column, message) in [
            (
                "error: /root/.cache/pocl/kcache/tempfile_EzTwFz.cl:64:3: use of undeclared \
                 identifier 'retur'",
                64,
                3,
                "use of undeclared identifier 'retur'",
            ),
            (
                "error: /tmp/t.cl:62:29 <Spelling=/tmp/t.cl:14:16>: expected ')'",
                62,
                29,
                "expected ')'",
            ),
            (
                "<stdin>:11:5: error: expected expression",
                11,
                5,
                "expected expression",
            ),
            (
                "<kernel>:7:1: error: unknown type name 'x'",
                7,
                1,
                "unknown type name 'x'",
            ),
            (
                "1:40:12: error: use of undeclared identifier",
                40,
                12,
                "use of undeclared identifier",
            ),
            (
                "input.cl:3:9: fatal error: 'x.h' file not found",
                3,
                9,
                "'x.h' file not found",
            ),
        ] {
            assert_eq!(
                diagnostics(log),
                vec![Diagnostic {
                    line,
                    column,
                    message: message.into()
                }],
                "{log}"
            );
        }
        let log = "warning: /tmp/t.cl:5:1: unused\n<stdin>:9:1: note: here\n2 errors generated.";
        assert!(diagnostics(log).is_empty());
    }

    #[test]
    fn an_error_in_a_custom_body_names_the_shape_and_its_line() {
        let log = "warning: /tmp/t.cl:2:1: something\n\
                   error: /tmp/t.cl:4:1: an error elsewhere\n\
                   error: /tmp/t.cl:11:6: expected expression\n\
                   2 errors generated."
            .to_string();
        match build_error("dev".into(), log.clone(), &program()) {
            Error::CustomShapeBuild {
                shape,
                line,
                column,
                text,
                message,
                build,
            } => {
                assert_eq!((shape.as_str(), line, column), ("gyroid", 2, 6));
                assert_eq!(text, "line 11");
                assert_eq!(message, "expected expression");
                assert!(matches!(*build, Error::Build { .. }));
                assert_eq!(build.build_log(), Some(log.as_str()));
                assert_eq!(build.kernel_source(), Some(program().source.as_str()));
            }
            other => panic!("{other:?}"),
        }
        let signature = build_error("dev".into(), "<stdin>:9:3: error: bad".into(), &program());
        assert!(
            signature
                .to_string()
                .starts_with("custom shape `gyroid`, in its signature `line 9`: bad"),
            "{signature}"
        );
        for outside in [
            "<stdin>:8:1: error: x",
            "<stdin>:13:1: error: x",
            "no location",
        ] {
            let err = build_error("dev".into(), outside.into(), &program());
            assert!(matches!(err, Error::Build { .. }), "{outside}: {err:?}");
        }
    }
}
