//! The helpers printed in WGSL: every module parses and validates with
//! naga (which reads WGSL as a WebGPU implementation does), and runs on a
//! Vulkan device through wgpu (Mesa's lavapipe where there is no GPU) to
//! the values of the very program it was printed from, interpreted on the
//! CPU in single precision.

mod device;

use std::cell::RefCell;

use device::{device, run};

use super::formulas;
use super::helpers::Helper;
use crate::expr::{Inline, Printer, Program, Shape, Signature, Unprintable, Wgsl};
use crate::quality::{Encoding, ToneMap};

/// Parses and validates `functions` after the printer's prelude.
fn validate(functions: &str) {
    let source = format!("{}\n{functions}", Wgsl::PRELUDE);
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
}

/// Every helper's source, trapped forms and integer Mandelbulb powers
/// included, by `to`.
fn every_helper(to: &dyn Printer) -> Vec<String> {
    let mut out = Vec::new();
    for h in Helper::ALL {
        out.push(h.source(to).unwrap());
        if let Some(trapped) = h.fractal_source(to, true) {
            out.push(trapped.unwrap());
        }
    }
    for n in 2..=9 {
        for trap in [false, true] {
            out.push(formulas::mandelbulb_power(to, n, trap).unwrap());
        }
    }
    out
}

#[test]
fn every_helper_is_valid_wgsl() {
    let functions = every_helper(&Wgsl).concat();
    assert!(functions.contains("fn sd_sphere(p: real3, r: real) -> real {"));
    validate(&functions);
}

#[test]
fn every_display_transform_is_valid_wgsl() {
    for tone_map in ToneMap::ALL {
        for encoding in [Encoding::Gamma, Encoding::Srgb] {
            validate(&formulas::display(&Wgsl, tone_map, encoding).unwrap());
        }
    }
}

/// The prelude's rounding takes halves away from zero on the device, as
/// OpenCL's `round` and the CPU reference do (`f32::round`), where WGSL's
/// own takes them to even; its finiteness test refuses NaN and both
/// infinities.
#[test]
fn the_prelude_rounds_halves_away_from_zero_on_the_device() {
    let Some(gpu) = device() else { return };
    let xs = [
        0.5f32,
        1.5,
        2.5,
        -0.5,
        -2.5,
        0.499_999_97,
        -0.499_999_97,
        3.2,
        -3.7,
        8_388_607.5,
        f32::MAX,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ];
    let n = xs.len();
    let source = format!(
        "{}\n\
         @group(0) @binding(0) var<storage, read> inputs: array<f32>;\n\
         @group(0) @binding(1) var<storage, read_write> outputs: array<f32>;\n\
         @compute @workgroup_size(64)\n\
         fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         \x20   let i = id.x;\n\
         \x20   if (i >= {n}u) {{ return; }}\n\
         \x20   outputs[2u * i] = fsdf_round(inputs[i]);\n\
         \x20   outputs[2u * i + 1u] = select(0.0, 1.0, fsdf_is_finite(inputs[i]));\n\
         }}\n",
        Wgsl::PRELUDE
    );
    let got = run(&gpu, &source, &[&xs], 2 * n, n);
    for (k, x) in xs.iter().enumerate() {
        if x.is_finite() {
            assert_eq!(got[2 * k], x.round(), "round({x})");
        }
        assert_eq!(got[2 * k + 1] == 1.0, x.is_finite(), "is_finite({x})");
    }
}

/// A printed function's name, parameters and result, and the program it
/// was printed from.
struct Recorded {
    name: String,
    params: Vec<(String, Shape)>,
    result: Shape,
    program: Program,
}

/// A printer that keeps what it is asked to print.
#[derive(Default)]
struct Recorder(RefCell<Vec<Recorded>>);

impl Printer for Recorder {
    fn function(&self, s: &Signature<'_>, program: &Program) -> Result<String, Unprintable> {
        self.0.borrow_mut().push(Recorded {
            name: s.name.to_string(),
            params: s
                .params
                .iter()
                .map(|(n, sh)| ((*n).to_string(), *sh))
                .collect(),
            result: s.result,
            program: program.clone(),
        });
        Ok(String::new())
    }

    fn inline(
        &self,
        _: &[(&str, Shape)],
        _: &[Shape],
        _: &Program,
        _: &str,
    ) -> Result<Inline, Unprintable> {
        unreachable!("helpers are functions")
    }
}

/// A compute shader that calls `f` on each point's inputs.
fn shader(f: &Recorded, wgsl: &str, points: usize) -> String {
    let stride = f.program.inputs;
    let width = f.result.width();
    let mut at = 0;
    let args: Vec<String> = f
        .params
        .iter()
        .map(|(_, shape)| {
            let read = |k: u32| format!("inputs[base + {}u]", at + k);
            let arg = match shape {
                Shape::Scalar => read(0),
                Shape::Pair => format!("real2({}, {})", read(0), read(1)),
                Shape::Vec3 => format!("real3({}, {}, {})", read(0), read(1), read(2)),
            };
            at += shape.width();
            arg
        })
        .collect();
    let stores = match f.result {
        Shape::Scalar => "outputs[i] = r;".to_string(),
        Shape::Pair => format!("outputs[i * {width}u] = r.x; outputs[i * {width}u + 1u] = r.y;"),
        Shape::Vec3 => format!(
            "outputs[i * {width}u] = r.x; outputs[i * {width}u + 1u] = r.y; \
             outputs[i * {width}u + 2u] = r.z;"
        ),
    };
    format!(
        "{}\n{wgsl}\n\
         @group(0) @binding(0) var<storage, read> inputs: array<f32>;\n\
         @group(0) @binding(1) var<storage, read_write> outputs: array<f32>;\n\
         @compute @workgroup_size(64)\n\
         fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         \x20   let i = id.x;\n\
         \x20   if (i >= {points}u) {{ return; }}\n\
         \x20   let base = i * {stride}u;\n\
         \x20   let r = {}({});\n\
         \x20   {stores}\n\
         }}\n",
        Wgsl::PRELUDE,
        f.name,
        args.join(", ")
    )
}

/// Every helper's WGSL, run on the device at 256 random inputs (points
/// in [-2, 2]³, every other number in [0.1, 2]: positive radii and sizes,
/// one or two fractal iterations), gives what the CPU computes running
/// the program the helper was printed from in `f32`, within the
/// difference of two single-precision libraries' `sin`, `pow` and `acos`.
#[test]
fn every_helper_runs_on_wgpu_as_its_program_does() {
    let Some(gpu) = device() else { return };
    let recorder = Recorder::default();
    let sources = every_helper(&recorder);
    assert!(sources.iter().all(String::is_empty));
    let points = 256;
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = |lo: f32, hi: f32| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((state >> 40) as f32 / (1u64 << 24) as f32)
    };
    let mut worst = (0.0f32, String::new());
    for f in recorder.0.borrow().iter() {
        let wgsl = Wgsl
            .function(
                &Signature::new(
                    &f.name,
                    &f.params
                        .iter()
                        .map(|(n, s)| (n.as_str(), *s))
                        .collect::<Vec<_>>(),
                    f.result,
                ),
                &f.program,
            )
            .unwrap();
        let stride = f.program.inputs as usize;
        let inputs: Vec<f32> = (0..points * stride)
            .map(|k| {
                if k % stride < 3 {
                    uniform(-2.0, 2.0)
                } else {
                    uniform(0.1, 2.0)
                }
            })
            .collect();
        let width = f.result.width() as usize;
        let got = run(
            &gpu,
            &shader(f, &wgsl, points),
            &[&inputs],
            points * width,
            points,
        );
        for (i, chunk) in inputs.chunks_exact(stride).enumerate() {
            let expected = f.program.run(chunk);
            for (k, &e) in expected.iter().enumerate() {
                let g = got[i * width + k];
                if !e.is_finite() {
                    continue;
                }
                let error = (g - e).abs() / e.abs().max(1.0);
                assert!(
                    error <= 1e-3,
                    "{}: output {k} at inputs {chunk:?}: device {g}, CPU {e}\n{wgsl}",
                    f.name
                );
                if error > worst.0 {
                    worst = (error, f.name.clone());
                }
            }
        }
    }
    assert!(
        recorder.0.borrow().len() > 60,
        "{}",
        recorder.0.borrow().len()
    );
    eprintln!("largest relative difference: {} in {}", worst.0, worst.1);
}

/// A literal single precision cannot hold is refused, not printed into a
/// shader that would fail to build.
#[test]
fn a_literal_beyond_single_precision_is_unprintable() {
    use crate::expr::{Num, Var, trace};
    let program = trace(1, |a| vec![a[0] * Var::of(1e39)]);
    let signature = Signature::new("big", &[("x", Shape::Scalar)], Shape::Scalar);
    assert_eq!(
        Wgsl.function(&signature, &program),
        Err(Unprintable::Literal(1e39))
    );
    let program = trace(1, |a| vec![a[0] * Var::of(3e38)]);
    validate(&Wgsl.function(&signature, &program).unwrap());
}
