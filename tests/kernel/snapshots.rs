//! The generated OpenCL C of every gallery scene, compared with the
//! committed files in `tests/snapshots/`: per scene, its own part (header,
//! helpers, `DE` and `DE_shade`); the marcher once per combination of
//! effects the scenes use (`tests/snapshots/kernels/`), as code generation
//! appends it. After an intended change to code generation or the kernels,
//! regenerate them with `make snapshots` (`UPDATE_SNAPSHOTS=1 cargo test
//! --test kernel snapshots`) and review the diff.

use std::collections::BTreeMap;
use std::path::PathBuf;

use fractal_sdf::codegen::{self, Effect, Options};
use fractal_sdf::gallery;
use fractal_sdf::prelude::*;

fn check(name: &str, source: &str) -> Result<(), String> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(format!("{name}.cl"));
    if std::env::var("UPDATE_SNAPSHOTS").as_deref() == Ok("1") {
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
    let f64_options = Options::default().quality(Quality::reference());
    cases.push(("mandelbulb_f64".into(), gallery::mandelbulb(), f64_options));
    let mut kernels = BTreeMap::new();
    let mut failures = Vec::new();
    for (name, scene, options) in &cases {
        let compiled = scene.compile().expect("gallery scenes are valid");
        let kernel = codegen::emit(&compiled, options).expect("gallery options are valid");
        failures.extend(check(name, kernel.scene_part()).err());
        let effects: Vec<&str> = Effect::enabled(options)
            .into_iter()
            .map(|e| e.switch().trim_start_matches("ENABLE_"))
            .collect();
        let key = format!("kernels/march_{}", effects.join("_").to_lowercase());
        kernels.insert(key, kernel.kernel_part().to_string());
    }
    for (name, kernel) in &kernels {
        failures.extend(check(name, kernel).err());
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
