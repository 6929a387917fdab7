//! The pipeline's modules depend only on earlier stages: nothing reaches
//! back (ARCHITECTURE.md). This reads every source file and checks each
//! `crate::module` a pipeline module's code names (doc comments aside)
//! against the stages before it.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Each pipeline module and the modules its code may name. Modules beside
/// the pipeline (animation, sequence, view, gallery, metrics, output,
/// testing) may name any stage; the only one a stage names is `view`, whose
/// `FrameTiming` the renderer reports.
const STAGES: &[(&str, &[&str])] = &[
    ("error", &[]),
    // The foundation: `math`'s vectors are generic over `expr`'s numbers,
    // and `expr`'s formulas use `math`'s vectors and guards.
    ("math", &["expr"]),
    ("expr", &["math"]),
    ("quality", &["error", "math"]),
    ("scene", &["error", "math", "expr"]),
    ("ir", &["error", "math", "expr", "scene"]),
    ("cpu", &["error", "scene", "ir", "math", "expr"]),
    // Code generation prints the formulas of `cpu::sdf` through `expr`.
    (
        "codegen",
        &["error", "scene", "ir", "math", "expr", "cpu", "quality"],
    ),
    (
        "render",
        &[
            "error", "scene", "ir", "math", "quality", "cpu", "codegen", "view",
        ],
    ),
    (
        "mesh",
        &[
            "error", "scene", "ir", "math", "quality", "cpu", "render", "output",
        ],
    ),
];

fn sources(at: &Path, out: &mut Vec<PathBuf>) {
    if at.is_dir() {
        for entry in std::fs::read_dir(at).unwrap() {
            sources(&entry.unwrap().path(), out);
        }
    } else if at.extension().is_some_and(|e| e == "rs") {
        out.push(at.to_path_buf());
    }
}

/// The `crate::name` modules named outside comments in `text`.
fn named_modules(text: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if name.is_empty() {
                // A group, `crate::{a, b::c}`: every first segment in it.
                let group = rest.trim_start_matches('{');
                let group = group.split('}').next().unwrap_or("");
                for item in group.split(',') {
                    let first = item.trim().split("::").next().unwrap_or("");
                    if !first.is_empty() {
                        names.insert(first.to_string());
                    }
                }
            } else {
                names.insert(name);
            }
        }
    }
    names
}

#[test]
fn no_stage_names_a_later_one() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut checked = 0;
    let mut wrong = Vec::new();
    for (stage, allowed) in STAGES {
        let mut files = Vec::new();
        let dir = src.join(stage);
        sources(
            &if dir.is_dir() {
                dir
            } else {
                src.join(format!("{stage}.rs"))
            },
            &mut files,
        );
        assert!(!files.is_empty(), "no sources for `{stage}`");
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            for name in named_modules(&text) {
                if name != *stage && !allowed.contains(&name.as_str()) {
                    wrong.push(format!("{}: names `crate::{name}`", file.display()));
                }
            }
            checked += 1;
        }
    }
    assert!(
        wrong.is_empty(),
        "a stage reaches back:\n{}",
        wrong.join("\n")
    );
    assert!(checked >= 20, "only {checked} files read");
}

#[test]
fn the_reader_finds_plain_grouped_and_nested_names() {
    let text = "use crate::ir::Ir;\nuse crate::{error::Error, scene};\n\
                let x = crate::cpu::f(); // crate::render in a comment\n/// [`x`](crate::codegen)";
    let names: Vec<String> = named_modules(text).into_iter().collect();
    assert_eq!(names, ["cpu", "error", "ir", "scene"]);
}
