//! CPU-side costs: lowering and code generation per gallery scene, and the
//! reference evaluator's distance per fractal.
//!
//! `cargo bench --bench pipeline`

use criterion::{Criterion, criterion_group, criterion_main};
use fractal_sdf::codegen::{self, Options};
use fractal_sdf::cpu::Evaluator;
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use std::hint::black_box;

fn codegen_per_scene(c: &mut Criterion) {
    let mut group = c.benchmark_group("emit");
    for (name, scene) in gallery::all() {
        let scene = scene.compile().unwrap();
        group.bench_function(name, |b| {
            b.iter(|| codegen::emit(black_box(&scene), &Options::default()).unwrap());
        });
    }
    group.finish();
    let scene = gallery::fractal_mix();
    c.bench_function("compile/fractal_mix", |b| {
        b.iter(|| black_box(&scene).compile().unwrap())
    });
}

fn distance_per_fractal(c: &mut Criterion) {
    let mut group = c.benchmark_group("cpu_distance");
    let points: Vec<DVec3> = (0..64)
        .map(|i| {
            let t = f64::from(i) * 0.37;
            dvec3(t.sin() * 1.1, (t * 1.3).cos() * 0.9, (t * 0.7).sin() * 1.2)
        })
        .collect();
    for name in ["mandelbulb", "menger", "julia", "sierpinski"] {
        let scene = gallery::by_name(name).unwrap();
        let eval = Evaluator::new(scene.geometry.as_ref().unwrap()).unwrap();
        group.bench_function(format!("{name}/f64"), |b| {
            b.iter(|| {
                points
                    .iter()
                    .map(|p| eval.distance(black_box(*p)))
                    .sum::<f64>()
            });
        });
        group.bench_function(format!("{name}/f32"), |b| {
            b.iter(|| {
                points
                    .iter()
                    .map(|p| eval.distance_f32(black_box(p.as_vec3())))
                    .sum::<f32>()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, codegen_per_scene, distance_per_fractal);
criterion_main!(benches);
