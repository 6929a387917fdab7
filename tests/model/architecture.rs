//! The pipeline's modules depend only on earlier stages: nothing reaches
//! back (ARCHITECTURE.md). This reads every source file and checks each
//! `crate::module` a pipeline module's code names (doc comments aside)
//! against the stages before it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Each pipeline module and the modules its code may name. Modules beside
/// the pipeline (animation, sequence, view, gallery, metrics, output,
/// testing) may name any stage; the only one a stage names is `view`, whose
/// `FrameTiming` the renderer reports.
const STAGES: &[(&str, &[&str])] = &[
    ("error", &[]),
    // The foundation: `expr`'s numbers, vectors and guards, over which
    // `math`'s helpers and every later stage's formulas are written.
    ("expr", &[]),
    ("math", &["expr"]),
    ("quality", &["error", "math", "expr"]),
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
            "error", "scene", "ir", "math", "expr", "quality", "cpu", "codegen", "view",
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

/// The modules directly inside `dir` (files and folders), by name.
fn children(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir() || (path.extension().is_some_and(|e| e == "rs") && name != "mod") {
            out.push((name, path));
        }
    }
    out.sort();
    out
}

/// The sibling a name in `dir`'s module refers to: a sibling module of
/// that name, or the sibling an item of that name is re-exported from
/// (`use sibling::{Item, ..}` in the module's own file).
fn resolve(
    name: &str,
    siblings: &BTreeSet<String>,
    reexports: &[(String, String)],
) -> Option<String> {
    if siblings.contains(name) {
        return Some(name.to_string());
    }
    reexports
        .iter()
        .find(|(item, _)| item == name)
        .map(|(_, from)| from.clone())
}

/// `(item, sibling)` for each `use sibling::...` in a module's own file.
fn reexports(text: &str, siblings: &BTreeSet<String>) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let code: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join(" ");
    for part in code.split("use ").skip(1) {
        let statement = part.split(';').next().unwrap_or("");
        let statement = statement.trim().trim_start_matches("self::");
        let Some((from, rest)) = statement.split_once("::") else {
            continue;
        };
        if !siblings.contains(from) {
            continue;
        }
        let rest = rest.trim().trim_start_matches('{').trim_end_matches('}');
        for item in rest.split(',') {
            let item = item.split(" as ").last().unwrap_or("").trim();
            let item = item.rsplit("::").next().unwrap_or("").trim();
            if !item.is_empty() {
                out.push((item.to_string(), from.to_string()));
            }
        }
    }
    out
}

/// The names after `prefix` (`super::` or `crate::a::b::`) outside comments.
fn names_after(text: &str, prefix: &str) -> BTreeSet<String> {
    // Comments out, lines joined: a `use` group may span lines.
    let code: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join(" ");
    let mut names = BTreeSet::new();
    let mut rest = code.as_str();
    while let Some(at) = rest.find(prefix) {
        rest = &rest[at + prefix.len()..];
        // `super::super::` names the module above: not a sibling.
        if prefix == "super::" && rest.starts_with("super::") {
            rest = &rest["super::".len()..];
            continue;
        }
        let items = match rest.strip_prefix('{') {
            Some(group) => top_level(group),
            None => vec![rest],
        };
        for item in items {
            let first: String = item
                .trim_start()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !first.is_empty() {
                names.insert(first);
            }
        }
    }
    names
}

/// The items of a `{...}` group (`group` starts after its `{`), split at
/// its own commas, not those of nested groups.
fn top_level(group: &str) -> Vec<&str> {
    let (mut depth, mut start, mut items) = (0, 0, Vec::new());
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(&group[start..i]);
                return items;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&group[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&group[start..]);
    items
}

/// Every import circle among the modules inside `dir` (named `path`), and
/// recursively inside each of them.
fn circles_in(dir: &Path, path: &str, out: &mut Vec<String>) {
    let kids = children(dir);
    let siblings: BTreeSet<String> = kids.iter().map(|(n, _)| n.clone()).collect();
    let own = if path.is_empty() {
        dir.join("lib.rs")
    } else {
        dir.join("mod.rs")
    };
    let own_text = std::fs::read_to_string(&own).unwrap_or_default();
    let exports = reexports(&own_text, &siblings);
    let crate_prefix = format!("crate::{path}{}", if path.is_empty() { "" } else { "::" });
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (name, at) in &kids {
        if name == "bin" || name == "lib" {
            continue;
        }
        let mut files = Vec::new();
        sources(at, &mut files);
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            // Unit tests may name any sibling: the circle is in the code.
            let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
            // `super::` means this module only in the sibling's own file.
            let direct = file == *at || file == at.join("mod.rs");
            let mut named = names_after(text, &crate_prefix);
            if direct && !path.is_empty() {
                named.extend(names_after(text, "super::"));
            }
            for n in named {
                if let Some(to) = resolve(&n, &siblings, &exports)
                    && to != *name
                {
                    edges.entry(name.clone()).or_default().insert(to);
                }
            }
        }
        if at.is_dir() {
            let inner = if path.is_empty() {
                name.clone()
            } else {
                format!("{path}::{name}")
            };
            circles_in(at, &inner, out);
        }
    }
    // A circle: a path from a module back to itself.
    for start in edges.keys() {
        let mut stack = vec![(start.clone(), vec![start.clone()])];
        let mut seen = BTreeSet::new();
        while let Some((at, trail)) = stack.pop() {
            for next in edges.get(&at).into_iter().flatten() {
                if next == start {
                    let mut trail = trail.clone();
                    trail.push(start.clone());
                    // Report each circle once, from its smallest member.
                    if trail.iter().all(|m| m >= start) {
                        out.push(format!("{path}: {}", trail.join(" -> ")));
                    }
                } else if seen.insert(next.clone()) {
                    let mut trail = trail.clone();
                    trail.push(next.clone());
                    stack.push((next.clone(), trail));
                }
            }
        }
    }
}

/// No two modules name each other, directly or round a circle: among the
/// top-level modules and among the modules inside each one. A module's own
/// file (`mod.rs`) is its facade and may re-export its children; a child
/// naming `super::Item` is held to the sibling that item comes from. Unit
/// test modules are left out.
#[test]
fn no_import_circles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut circles = Vec::new();
    circles_in(&src, "", &mut circles);
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

/// A module tree written to a temporary folder: `a` names `b` through a
/// group over two lines, `b` names `a` through an item `a` exports.
#[test]
fn the_circle_finder_finds_a_circle_in_a_tree() {
    let root = std::env::temp_dir().join(format!("fractal-sdf-circles-{}", std::process::id()));
    let top = root.join("top");
    std::fs::create_dir_all(&top).unwrap();
    std::fs::write(top.join("mod.rs"), "mod a;\nmod b;\npub use a::Thing;\n").unwrap();
    std::fs::write(
        top.join("a.rs"),
        "use crate::top::{\n    b::More,\n};\npub struct Thing;\n",
    )
    .unwrap();
    std::fs::write(
        top.join("b.rs"),
        "use super::Thing; // from a\npub struct More;\n",
    )
    .unwrap();
    std::fs::write(top.join("c.rs"), "use super::b::More;\n").unwrap();
    std::fs::write(root.join("lib.rs"), "mod top;\n").unwrap();
    let mut circles = Vec::new();
    circles_in(&root, "", &mut circles);
    std::fs::remove_dir_all(&root).unwrap();
    assert_eq!(circles, ["top: a -> b -> a"]);
}

#[test]
fn the_circle_finder_finds_a_circle() {
    let siblings: BTreeSet<String> = ["a", "b"].map(String::from).into();
    let exports = reexports("pub use a::{Thing, Other};\nuse b::More;", &siblings);
    assert_eq!(resolve("Thing", &siblings, &exports).as_deref(), Some("a"));
    assert_eq!(resolve("More", &siblings, &exports).as_deref(), Some("b"));
    assert_eq!(resolve("b", &siblings, &exports).as_deref(), Some("b"));
    let named = names_after(
        "use super::{Thing, b::{x, y}, d};\nsuper::super::c",
        "super::",
    );
    assert_eq!(named.into_iter().collect::<Vec<_>>(), ["Thing", "b", "d"]);
}
