//! The public API as a reviewed listing: every item a user can name, read
//! from the sources with `syn` (no nightly rustdoc needed), is written to
//! `tests/snapshots/public-api.txt`, so every change to the surface shows in
//! review. The same walk holds the API rules of the guide's architecture
//! chapter: public enums and options structs are `#[non_exhaustive]`, the
//! prelude stays small, and each item has one public path.
//!
//! `UPDATE_SNAPSHOTS=1 cargo test --test model public_api` rewrites the
//! listing.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use quote::ToTokens;
use syn::{Attribute, Fields, ImplItem, Item, TraitItem, UseTree, Visibility};

/// One public item where it is defined: its kind line and the lines of its
/// fields, variants and trait methods.
struct Def {
    module: String,
    name: String,
    /// `struct`, `enum`, `fn`, ... with `#[non_exhaustive]` where present.
    head: String,
    members: Vec<String>,
    kind: Kind,
    non_exhaustive: bool,
}

#[derive(PartialEq)]
enum Kind {
    Enum,
    /// A struct with public named fields.
    Options,
    Other,
}

/// What the walk found, in every module, public or not.
#[derive(Default)]
struct Crate {
    defs: Vec<Def>,
    /// Module path -> whether every module on its path is public.
    modules: BTreeMap<String, bool>,
    /// `pub use`: (module, absolute target, name it is used as).
    uses: Vec<(String, String, String)>,
    /// Inherent methods and trait impls: (module, type name, line).
    impls: Vec<(String, String, String)>,
    macros: Vec<String>,
    /// The traits no one outside the crate can name: their impls are not
    /// part of the API.
    private_traits: BTreeSet<String>,
}

fn is_pub(vis: &Visibility) -> bool {
    matches!(vis, Visibility::Public(_))
}

fn has_attr(attrs: &[Attribute], name: &str) -> bool {
    attrs.iter().any(|a| a.path().is_ident(name))
}

/// `#[doc(hidden)]` items are not part of the API.
fn hidden(attrs: &[Attribute]) -> bool {
    attrs
        .iter()
        .any(|a| a.path().is_ident("doc") && a.to_token_stream().to_string().contains("hidden"))
}

/// The `#[cfg(...)]` on an item, for the listing.
fn cfg(attrs: &[Attribute]) -> String {
    attrs
        .iter()
        .filter(|a| a.path().is_ident("cfg"))
        .map(|a| format!(" [{}]", tokens(&a.meta)))
        .collect()
}

/// Tokens as one line, with the spacing `quote` gives, tidied a little.
fn tokens(t: &impl ToTokens) -> String {
    t.to_token_stream()
        .to_string()
        .replace(" :: ", "::")
        .replace(" ,", ",")
        .replace("& ", "&")
        .replace(" < ", "<")
        .replace(" >", ">")
        .replace("< ", "<")
}

fn module_file(dir: &Path, name: &str) -> (PathBuf, PathBuf) {
    let flat = dir.join(format!("{name}.rs"));
    if flat.exists() {
        (flat, dir.join(name))
    } else {
        (dir.join(name).join("mod.rs"), dir.join(name))
    }
}

fn walk_file(file: &Path, dir: &Path, path: &str, public: bool, c: &mut Crate) {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{file:?}: {e}"));
    let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{file:?}: {e}"));
    c.modules.insert(path.to_string(), public);
    walk_items(&parsed.items, dir, path, public, c);
}

/// A `use` target as an absolute path from inside `module`.
fn absolute(module: &str, target: &str) -> String {
    if let Some(rest) = target.strip_prefix("crate::") {
        format!("fractal_sdf::{rest}")
    } else if let Some(rest) = target.strip_prefix("self::") {
        format!("{module}::{rest}")
    } else if let Some(rest) = target.strip_prefix("super::") {
        format!(
            "{}::{rest}",
            module.rsplit_once("::").map_or("", |(p, _)| p)
        )
    } else {
        // A 2018 path: a child module, or another crate (left as written).
        format!("{module}::{target}")
    }
}

fn walk_items(items: &[Item], dir: &Path, path: &str, public: bool, c: &mut Crate) {
    let def = |c: &mut Crate, name: String, head: String, members, kind, non_exhaustive| {
        c.defs.push(Def {
            module: path.to_string(),
            name,
            head,
            members,
            kind,
            non_exhaustive,
        })
    };
    for item in items {
        match item {
            Item::Mod(m) if !hidden(&m.attrs) && !has_test_cfg(&m.attrs) => {
                let inner = format!("{path}::{}", m.ident);
                let public = public && is_pub(&m.vis);
                match &m.content {
                    Some((_, items)) => {
                        c.modules.insert(inner.clone(), public);
                        walk_items(items, &dir.join(m.ident.to_string()), &inner, public, c)
                    }
                    None => {
                        let (file, sub) = module_file(dir, &m.ident.to_string());
                        walk_file(&file, &sub, &inner, public, c);
                    }
                }
            }
            Item::Fn(f) if is_pub(&f.vis) && !hidden(&f.attrs) => {
                let head = format!("{}{}", tokens(&f.sig), cfg(&f.attrs));
                def(c, f.sig.ident.to_string(), head, vec![], Kind::Other, false);
            }
            Item::Struct(st) if is_pub(&st.vis) && !hidden(&st.attrs) => {
                let ne = has_attr(&st.attrs, "non_exhaustive");
                let head = format!(
                    "{}struct{}{}",
                    if ne { "#[non_exhaustive] " } else { "" },
                    tokens(&st.generics),
                    cfg(&st.attrs)
                );
                let members: Vec<String> = st
                    .fields
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| is_pub(&f.vis))
                    .map(|(i, f)| {
                        let id = f.ident.as_ref().map_or(i.to_string(), |i| i.to_string());
                        format!(".{id}: {}", tokens(&f.ty))
                    })
                    .collect();
                let kind = if !members.is_empty() && matches!(st.fields, Fields::Named(_)) {
                    Kind::Options
                } else {
                    Kind::Other
                };
                def(c, st.ident.to_string(), head, members, kind, ne);
            }
            Item::Enum(e) if is_pub(&e.vis) && !hidden(&e.attrs) => {
                let ne = has_attr(&e.attrs, "non_exhaustive");
                let head = format!(
                    "{}enum{}{}",
                    if ne { "#[non_exhaustive] " } else { "" },
                    tokens(&e.generics),
                    cfg(&e.attrs)
                );
                let members = e
                    .variants
                    .iter()
                    .map(|v| format!("::{}{}", v.ident, fields_sig(&v.fields)))
                    .collect();
                def(c, e.ident.to_string(), head, members, Kind::Enum, ne);
            }
            Item::Trait(t) if !is_pub(&t.vis) => {
                c.private_traits.insert(t.ident.to_string());
            }
            Item::Trait(t) if is_pub(&t.vis) && !hidden(&t.attrs) => {
                let members = t
                    .items
                    .iter()
                    .filter_map(|ti| match ti {
                        TraitItem::Fn(f) => Some(format!("::{}", tokens(&f.sig))),
                        TraitItem::Type(t) => Some(format!("::type {}", t.ident)),
                        TraitItem::Const(k) => Some(format!("::const {}", k.ident)),
                        _ => None,
                    })
                    .collect();
                let head = format!("trait{}{}", tokens(&t.generics), cfg(&t.attrs));
                def(c, t.ident.to_string(), head, members, Kind::Other, false);
            }
            Item::Const(k) if is_pub(&k.vis) && !hidden(&k.attrs) => {
                let head = format!("const: {}", tokens(&k.ty));
                def(c, k.ident.to_string(), head, vec![], Kind::Other, false);
            }
            Item::Static(k) if is_pub(&k.vis) && !hidden(&k.attrs) => {
                let head = format!("static: {}", tokens(&k.ty));
                def(c, k.ident.to_string(), head, vec![], Kind::Other, false);
            }
            Item::Type(t) if is_pub(&t.vis) && !hidden(&t.attrs) => {
                let head = format!("type = {}", tokens(&t.ty));
                def(c, t.ident.to_string(), head, vec![], Kind::Other, false);
            }
            Item::Use(u) if is_pub(&u.vis) && !hidden(&u.attrs) => {
                let mut targets = Vec::new();
                flatten_use(&u.tree, String::new(), &mut targets);
                for (target, name) in targets {
                    c.uses
                        .push((path.to_string(), absolute(path, &target), name));
                }
            }
            Item::Impl(i) if !hidden(&i.attrs) && !has_test_cfg(&i.attrs) => {
                let ty = match &*i.self_ty {
                    syn::Type::Path(p) => p.path.segments.last().unwrap().ident.to_string(),
                    other => tokens(other),
                };
                if let Some((_, t, _)) = &i.trait_ {
                    let line = format!("impl {}{}", tokens(t), cfg(&i.attrs));
                    c.impls.push((path.to_string(), ty, line));
                    continue;
                }
                for ii in &i.items {
                    match ii {
                        ImplItem::Fn(f) if is_pub(&f.vis) && !hidden(&f.attrs) => {
                            let line = format!("::{}{}", tokens(&f.sig), cfg(&f.attrs));
                            c.impls.push((path.to_string(), ty.clone(), line));
                        }
                        ImplItem::Const(k) if is_pub(&k.vis) => {
                            let line = format!("::{}: {}", k.ident, tokens(&k.ty));
                            c.impls.push((path.to_string(), ty.clone(), line));
                        }
                        _ => {}
                    }
                }
            }
            Item::Macro(m) if has_attr(&m.attrs, "macro_export") => {
                let name = m.ident.as_ref().map(|i| i.to_string()).unwrap_or_default();
                c.macros.push(format!("macro fractal_sdf::{name}!"));
            }
            // A local `macro_rules!` that defines a public type (`keys!`
            // makes `Key`): the type, as the macro writes it.
            Item::Macro(m) if m.ident.is_some() && !has_attr(&m.attrs, "macro_export") => {
                let body = tokens(&m.mac.tokens);
                for kind in ["enum", "struct"] {
                    let marker = format!("pub {kind} ");
                    for (at, _) in body.match_indices(&marker) {
                        let name: String = body[at + marker.len()..]
                            .chars()
                            .take_while(|c| c.is_alphanumeric() || *c == '_')
                            .collect();
                        let ne = body[..at].trim_end().ends_with("# [non_exhaustive]");
                        let head = format!(
                            "{}{kind} (made by {}!)",
                            if ne { "#[non_exhaustive] " } else { "" },
                            m.ident.as_ref().unwrap()
                        );
                        let kind = if kind == "enum" {
                            Kind::Enum
                        } else {
                            Kind::Other
                        };
                        def(c, name, head, vec![], kind, ne);
                    }
                }
            }
            // `setters!(Type { field: Ty, .. })`: a setter per field.
            Item::Macro(m) if m.mac.path.is_ident("setters") => {
                let (ty, fields) = m
                    .mac
                    .parse_body_with(parse_setters)
                    .unwrap_or_else(|e| panic!("setters! in {path}: {e}"));
                for (field, t) in fields {
                    let line = format!("::fn {field} (mut self, {field} : {t}) -> Self [setters!]");
                    c.impls.push((path.to_string(), ty.clone(), line));
                }
            }
            // Any other macro that makes items (`keys!`): listed whole, so
            // a change to what it makes shows here too.
            Item::Macro(m) if m.ident.is_none() && !m.mac.path.is_ident("thread_local") => {
                c.macros.push(format!(
                    "{path}: {}! {}",
                    tokens(&m.mac.path),
                    tokens(&m.mac.tokens)
                ));
            }
            _ => {}
        }
    }
}

/// A variant's fields without their documentation.
fn fields_sig(fields: &Fields) -> String {
    let list = |named: bool| -> String {
        fields
            .iter()
            .map(|f| match (&f.ident, named) {
                (Some(id), true) => format!("{id}: {}", tokens(&f.ty)),
                _ => tokens(&f.ty),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    match fields {
        Fields::Named(_) => format!(" {{ {} }}", list(true)),
        Fields::Unnamed(_) => format!("({})", list(false)),
        Fields::Unit => String::new(),
    }
}

/// The type and the `(field, type)` pairs of a `setters!` invocation.
fn parse_setters(input: syn::parse::ParseStream) -> syn::Result<(String, Vec<(String, String)>)> {
    let ty: syn::Ident = input.parse()?;
    let body;
    syn::braced!(body in input);
    let mut fields = Vec::new();
    while !body.is_empty() {
        let _docs = body.call(Attribute::parse_outer)?;
        let field: syn::Ident = body.parse()?;
        body.parse::<syn::Token![:]>()?;
        let t: syn::Type = body.parse()?;
        fields.push((field.to_string(), tokens(&t)));
        if !body.is_empty() {
            body.parse::<syn::Token![,]>()?;
        }
    }
    Ok((ty.to_string(), fields))
}

fn has_test_cfg(attrs: &[Attribute]) -> bool {
    attrs
        .iter()
        .any(|a| a.path().is_ident("cfg") && tokens(&a.meta) == "cfg (test)")
}

/// `a::{b, c::d as e}` as (`a::b`, `b`), (`a::c::d`, `e`).
fn flatten_use(tree: &UseTree, prefix: String, out: &mut Vec<(String, String)>) {
    let join = |p: &str, x: &str| {
        if p.is_empty() {
            x.to_string()
        } else {
            format!("{p}::{x}")
        }
    };
    match tree {
        UseTree::Path(p) => flatten_use(&p.tree, join(&prefix, &p.ident.to_string()), out),
        UseTree::Name(n) => out.push((join(&prefix, &n.ident.to_string()), n.ident.to_string())),
        UseTree::Rename(r) => out.push((join(&prefix, &r.ident.to_string()), r.rename.to_string())),
        UseTree::Glob(_) => out.push((join(&prefix, "*"), "*".into())),
        UseTree::Group(g) => {
            for t in &g.items {
                flatten_use(t, prefix.clone(), out);
            }
        }
    }
}

/// The public API: each definition with every public path that names it.
struct Surface {
    krate: Crate,
    /// Index into `krate.defs` -> its public paths, sorted.
    paths: BTreeMap<usize, BTreeSet<String>>,
    /// Re-exports of other crates' items: public path -> target.
    foreign: BTreeSet<String>,
}

impl Surface {
    fn read() -> Surface {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut krate = Crate::default();
        walk_file(&src.join("lib.rs"), &src, "fractal_sdf", true, &mut krate);
        let mut by_place: BTreeMap<(String, String), usize> = BTreeMap::new();
        let mut paths: BTreeMap<usize, BTreeSet<String>> = BTreeMap::new();
        for (i, d) in krate.defs.iter().enumerate() {
            by_place.insert((d.module.clone(), d.name.clone()), i);
            if krate.modules[&d.module] {
                paths
                    .entry(i)
                    .or_default()
                    .insert(format!("{}::{}", d.module, d.name));
            }
        }
        // Follow `pub use` chains until nothing new is reached: a re-export
        // in a reachable module makes its target reachable under its name.
        let mut foreign = BTreeSet::new();
        let mut aliases: BTreeMap<(String, String), String> = BTreeMap::new();
        loop {
            let mut changed = false;
            for (module, target, name) in &krate.uses {
                let (from, item) = target.rsplit_once("::").unwrap();
                let from = aliases
                    .get(&split(from))
                    .cloned()
                    .unwrap_or_else(|| from.to_string());
                let reachable = krate.modules.get(module).copied().unwrap_or(false);
                let mut reach = |i: usize, as_name: &str| {
                    if reachable {
                        changed |= paths
                            .entry(i)
                            .or_default()
                            .insert(format!("{module}::{as_name}"));
                    }
                };
                if item == "*" {
                    let found: Vec<(usize, String)> = krate
                        .defs
                        .iter()
                        .enumerate()
                        .filter(|(_, d)| d.module == from)
                        .map(|(i, d)| (i, d.name.clone()))
                        .collect();
                    for (i, n) in found {
                        reach(i, &n);
                    }
                } else if let Some(&i) = by_place.get(&(from.clone(), item.to_string())) {
                    reach(i, name);
                    if by_place.insert((module.clone(), name.clone()), i).is_none() {
                        changed = true;
                    }
                } else if krate.modules.contains_key(&format!("{from}::{item}")) {
                    // A module re-exported under another name.
                    let alias = (module.clone(), name.clone());
                    if aliases.insert(alias, format!("{from}::{item}")).is_none() {
                        changed = true;
                    }
                    if reachable {
                        foreign.insert(format!("use {module}::{name} = {from}::{item}"));
                    }
                } else if reachable && !from.starts_with("fractal_sdf") {
                    foreign.insert(format!(
                        "use {module}::{name} = {}",
                        target.rsplit("fractal_sdf::").next().unwrap()
                    ));
                } else if reachable && !krate.modules.contains_key(&from) {
                    // Another crate's item through a 2018 path (`glam::DVec3`).
                    let written = target
                        .strip_prefix(&format!("{module}::"))
                        .unwrap_or(target);
                    foreign.insert(format!("use {module}::{name} = {written}"));
                } else if reachable && from == *module && !krate.modules.contains_key(target) {
                    // A whole crate (`pub use glam;`).
                    foreign.insert(format!("use {module}::{name} = {item}"));
                } else if reachable && !by_place.contains_key(&(module.clone(), name.clone())) {
                    panic!("`pub use {target}` in {module} names nothing the listing knows");
                }
            }
            if !changed {
                break;
            }
        }
        Surface {
            krate,
            paths,
            foreign,
        }
    }

    /// The public definitions, each with its canonical path: the first
    /// outside the prelude.
    fn public(&self) -> impl Iterator<Item = (&Def, &String)> {
        self.paths.iter().filter_map(|(&i, p)| {
            let canonical = p
                .iter()
                .find(|p| !p.starts_with("fractal_sdf::prelude::"))
                .or_else(|| p.iter().next())?;
            Some((&self.krate.defs[i], canonical))
        })
    }

    /// Public paths outside the prelude, for each public definition.
    fn outside_prelude(&self) -> impl Iterator<Item = (&Def, Vec<&String>)> {
        self.paths.iter().map(|(&i, p)| {
            let outside = p
                .iter()
                .filter(|p| !p.starts_with("fractal_sdf::prelude::"))
                .collect();
            (&self.krate.defs[i], outside)
        })
    }
}

fn split(path: &str) -> (String, String) {
    let (a, b) = path.rsplit_once("::").unwrap_or(("", path));
    (a.to_string(), b.to_string())
}

/// The listing: each public item at its canonical path (the first outside
/// the prelude), its members, its methods, and every other path naming it.
fn listing(s: &Surface) -> (String, [usize; 3]) {
    let mut lines = BTreeSet::new();
    let (mut items, mut methods, mut fields) = (0, 0, 0);
    for (def, canonical) in s.public() {
        items += 1;
        lines.insert(format!("{canonical}: {}", def.head));
        for m in &def.members {
            if m.starts_with('.') {
                fields += 1;
            }
            lines.insert(format!("{canonical}{m}"));
        }
        for (module, ty, line) in &s.krate.impls {
            if let Some(name) = line.strip_prefix("impl ")
                && s.krate
                    .private_traits
                    .contains(name.split('<').next().unwrap_or(name).trim())
            {
                continue;
            }
            // A method belongs to the type of that name in the impl's
            // top-level module, else to the one type of that name.
            if ty == &def.name && owner(s, module, ty).is_some_and(|o| std::ptr::eq(o, def)) {
                if line.starts_with("::") {
                    methods += 1;
                    lines.insert(format!("{canonical}{line}"));
                } else {
                    lines.insert(format!("{canonical}: {line}"));
                }
            }
        }
        for other in s.paths[&index(s, def)].iter().filter(|p| *p != canonical) {
            lines.insert(format!("use {other} = {canonical}"));
        }
    }
    for m in &s.krate.modules {
        if *m.1 {
            lines.insert(format!("mod {}", m.0));
        }
    }
    lines.extend(s.foreign.iter().cloned());
    lines.extend(s.krate.macros.iter().cloned());
    let mut out = String::from(
        "# The public API of fractal-sdf, one line per item, member, method and\n\
         # path (tests/model/public_api.rs; UPDATE_SNAPSHOTS=1 rewrites it).\n",
    );
    for line in &lines {
        writeln!(out, "{line}").unwrap();
    }
    (out, [items, methods, fields])
}

/// The definition an `impl ty` in `module` is for.
fn owner<'a>(s: &'a Surface, module: &str, ty: &str) -> Option<&'a Def> {
    let named: Vec<&Def> = s.krate.defs.iter().filter(|d| d.name == ty).collect();
    named
        .iter()
        .find(|d| top(&d.module) == top(module))
        .or_else(|| (named.len() == 1).then(|| &named[0]))
        .copied()
}

/// The crate's top-level module a path is in (`fractal_sdf::scene`).
fn top(path: &str) -> &str {
    let mut ends = path.match_indices("::").map(|(i, _)| i);
    let _crate_end = ends.next();
    ends.next().map_or(path, |i| &path[..i])
}

fn index(s: &Surface, def: &Def) -> usize {
    s.krate
        .defs
        .iter()
        .position(|d| std::ptr::eq(d, def))
        .unwrap()
}

#[test]
fn public_api_matches_its_snapshot() {
    let s = Surface::read();
    let (text, [items, methods, fields]) = listing(&s);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots/public-api.txt");
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    eprintln!("public API: {items} items, {methods} methods, {fields} public fields");
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != text {
        let old: BTreeSet<&str> = committed.lines().collect();
        let new: BTreeSet<&str> = text.lines().collect();
        let mut diff = String::new();
        for gone in old.difference(&new) {
            writeln!(diff, "- {gone}").unwrap();
        }
        for added in new.difference(&old) {
            writeln!(diff, "+ {added}").unwrap();
        }
        panic!(
            "the public API changed; review the difference and run \
             `UPDATE_SNAPSHOTS=1 cargo test --test model public_api`:\n{diff}"
        );
    }
}

/// At least 90% of the public enums and of the structs with public fields
/// can grow without a breaking change.
#[test]
fn enums_and_options_structs_are_non_exhaustive() {
    let s = Surface::read();
    let open: Vec<(&Def, &String)> = s.public().filter(|(d, _)| d.kind != Kind::Other).collect();
    let closed: Vec<&String> = open
        .iter()
        .filter(|(d, _)| !d.non_exhaustive)
        .map(|(_, p)| *p)
        .collect();
    let share = 1.0 - closed.len() as f64 / open.len() as f64;
    eprintln!(
        "{} of {} non_exhaustive; exhaustive: {closed:#?}",
        open.len() - closed.len(),
        open.len()
    );
    assert!(
        share >= 0.9,
        "{:.0}% non_exhaustive; exhaustive: {closed:#?}",
        share * 100.0
    );
    // The exceptions, each plain data written as a literal: a loop step
    // returned by users' formulas, and a region of generated source.
    let allowed = [
        "fractal_sdf::expr::Step",
        "fractal_sdf::codegen::CustomRegion",
    ];
    let unexpected: Vec<&&String> = closed
        .iter()
        .filter(|n| !allowed.contains(&n.as_str()))
        .collect();
    assert!(
        unexpected.is_empty(),
        "exhaustive without a reason: {unexpected:#?}"
    );
}

/// The prelude holds what a first scene needs, and no more.
#[test]
fn prelude_is_small() {
    let s = Surface::read();
    let names: Vec<&String> = s
        .krate
        .uses
        .iter()
        .filter(|(module, _, _)| module == "fractal_sdf::prelude")
        .map(|(_, _, name)| name)
        .collect();
    assert!(
        names.len() <= 25,
        "the prelude has {} names: {names:?}",
        names.len()
    );
}

/// Each item has one public path outside the prelude (a glob import's
/// convenience, which only repeats names).
#[test]
fn one_public_path_per_item() {
    let s = Surface::read();
    let twice: Vec<String> = s
        .outside_prelude()
        .filter(|(_, paths)| paths.len() > 1)
        .map(|(_, paths)| format!("{paths:?}"))
        .collect();
    assert!(twice.is_empty(), "items at two public paths: {twice:#?}");
}
