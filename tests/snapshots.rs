//! The generated OpenCL C of every gallery scene, compared with the
//! committed files in `tests/snapshots/`. After an intended change to code
//! generation or the kernels, regenerate them with `make snapshots`
//! (`UPDATE_SNAPSHOTS=1 cargo test --test snapshots`) and review the diff.

use std::path::PathBuf;

use fractal_sdf::codegen::{self, Options};
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;

fn check(name: &str, source: &str) -> Result<(), String> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(format!("{name}.cl"));
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        std::fs::write(&path, source).map_err(|e| format!("{}: {e}", path.display()))?;
        return Ok(());
    }
    let committed = std::fs::read_to_string(&path)
        .map_err(|e| format!("{}: {e} (run `make snapshots`)", path.display()))?;
    if committed == source {
        return Ok(());
    }
    let line = committed
        .lines()
        .zip(source.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| committed.lines().count().min(source.lines().count()));
    Err(format!(
        "{name}: generated source differs from {} at line {}:\n  committed: {:?}\n  generated: {:?}\n\
         If the change is intended, run `make snapshots` and review the diff.",
        path.display(),
        line + 1,
        committed.lines().nth(line).unwrap_or("<end of file>"),
        source.lines().nth(line).unwrap_or("<end of file>"),
    ))
}

#[test]
fn generated_sources_match_the_committed_snapshots() {
    let mut cases: Vec<(String, Scene, Options)> = gallery::all()
        .into_iter()
        .map(|(name, scene)| (name.to_string(), scene, Options::default()))
        .collect();
    let f64_options = Options {
        quality: Quality::reference(),
        ..Options::default()
    };
    cases.push(("mandelbulb_f64".into(), gallery::mandelbulb(), f64_options));
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|(name, scene, options)| {
            let kernel = codegen::emit(scene, options).expect("gallery scenes are valid");
            check(name, &kernel.source).err()
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(cases.len() >= 8);
}
