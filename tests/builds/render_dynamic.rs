//! Dynamic scenes: animated parameters change the image every frame with
//! no new program; frame timings; frame sequences on disk.
//!
//! The tests here take turns (`serial`), so the process-wide count of
//! program builds sees only the test that reads it.

use crate::gpu;

use fractal_sdf::animation::Motion;
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;
use fractal_sdf::render::{Renderer, program_builds};
use fractal_sdf::sequence::Sequence;

use crate::serial;

fn set(renderer: &mut Renderer, motions: &[Motion], time: f64) {
    for m in motions {
        for (name, value) in m.values(time) {
            renderer.set_param(&name, value).unwrap();
        }
    }
}

#[test]
fn animated_parameters_change_frames_without_a_rebuild() {
    let Some(_) = gpu::device() else { return };
    let _turn = serial();
    let (w, h) = (48, 36);
    for name in ["fractal_mix", "benchmark"] {
        let motions = gallery::motions(name);
        assert!(!motions.is_empty(), "{name} is animated");
        let mut r = Renderer::new(&gallery::by_name(name).unwrap(), Quality::draft()).unwrap();
        let (builds, total) = (r.builds(), program_builds());
        set(&mut r, &motions, 0.0);
        let first = r.render(w, h).unwrap();
        // A quarter period later: the power is at its peak, the moon a
        // quarter turn round.
        set(&mut r, &motions, 1.25);
        let second = r.render(w, h).unwrap();
        gpu::save(&format!("dynamic_{name}_0"), &first);
        gpu::save(&format!("dynamic_{name}_1"), &second);
        assert_eq!(r.builds(), builds, "{name}: no new program");
        assert_eq!(program_builds(), total, "{name}: nothing compiled");
        let differing = first
            .pixels()
            .zip(second.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            differing > (w * h / 100) as usize,
            "{name}: only {differing} pixels changed"
        );
        // Back at the start: the same image.
        set(&mut r, &motions, 0.0);
        assert_eq!(r.render(w, h).unwrap(), first, "{name}");
    }
}

#[test]
fn every_frame_reports_its_timing() {
    let Some(_) = gpu::device() else { return };
    let _turn = serial();
    let mut r = Renderer::new(&gpu::sphere_box_floor(), Quality::draft()).unwrap();
    assert_eq!(r.last_timing(), None);
    r.render(32, 24).unwrap();
    let t = r.last_timing().unwrap();
    // The parts lie within the whole call.
    assert!(
        t.kernel > std::time::Duration::ZERO && t.kernel <= t.total,
        "{t:?}"
    );
    assert!(t.readback <= t.total, "{t:?}");
    r.render_with_aovs(16, 12).unwrap();
    assert!(r.last_timing().is_some());
    // A failed frame leaves no timing behind.
    assert!(r.render(0, 12).is_err());
    assert_eq!(r.last_timing(), None);
}

#[test]
fn a_sequence_renders_its_frames_and_resumes() {
    let Some(_) = gpu::device() else { return };
    let _turn = serial();
    let dir = std::env::temp_dir().join(format!("fractal-sdf-seq-render-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scene = gallery::benchmark();
    let path = gallery::benchmark_path().unwrap();
    let seq = Sequence::new(&dir, 1.0, 4).unwrap();
    let mut r = Renderer::new(&scene, Quality::draft()).unwrap();
    let motions = gallery::motions("benchmark");
    let mut seen = Vec::new();
    seq.render(&mut r, &path, &motions, &[0, 2], (32, 24), |f| {
        assert!(f.path.is_file());
        seen.push(f.index);
    })
    .unwrap();
    assert_eq!(seen, [0, 2]);
    assert_eq!(seq.remaining(0..4, (32, 24)), [1, 3]);
    let todo = seq.remaining(0..4, (32, 24));
    seq.render(&mut r, &path, &motions, &todo, (32, 24), |_| {})
        .unwrap();
    assert!(seq.remaining(0..4, (32, 24)).is_empty());
    let frame = |i| image::open(seq.frame_path(i)).unwrap().to_rgba8();
    assert_eq!(frame(0).dimensions(), (32, 24));
    assert_ne!(frame(0), frame(1), "the camera moves along the path");
    std::fs::remove_dir_all(dir).unwrap();
}
