#!/usr/bin/env bash
# The crate as a user gets it: built from its own package, and the README's
# program run against that package. Called by scripts/test.sh.
#
# 1. `cargo package` writes target/package/fractal-sdf-VERSION.crate and
#    builds the library from the unpacked tarball, so a file the package
#    leaves out (a kernel, a module) or a path that leads outside it fails
#    here, not on crates.io.
# 2. The .crate is unpacked into target/package-check/, next to a new crate
#    that depends on it by path (the path form of the README's dependency
#    line) and whose src/main.rs is the README's program, cut from README.md
#    between the `readme-program` markers, so the two cannot drift apart.
# 3. That program renders a PNG on the OpenCL device (with
#    FRACTAL_SDF_REQUIRE_DEVICE=1, as test.sh sets, nothing may be skipped)
#    and a second binary checks that the PNG shows a shaded surface, not a
#    blank or the sky alone.
#
# The new crate builds into the crate's own target directory, with the
# package's Cargo.lock and the profile settings the package declares, so it
# reuses every dependency step 1 compiled: only the library itself is
# compiled again (from the unpacked copy).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
CARGO=${CARGO:-cargo}

say() { printf 'package-check: %s\n' "$*"; }
fail() {
    printf 'package-check: %s\n' "$*" >&2
    exit 1
}

start=$(date +%s)
name=fractal-sdf
version=$(sed -n 's/^version = "\(.*\)"$/\1/p' Cargo.toml | head -n 1)
[ -n "$version" ] || fail "no version in Cargo.toml"
target_dir=$("$CARGO" metadata --quiet --format-version 1 --no-deps | jq -r .target_directory)
[ -n "$target_dir" ] || fail "cargo metadata names no target directory"
crate_file="$target_dir/package/$name-$version.crate"
work="$target_dir/package-check"

# --- 1. Package and verify ----------------------------------------------------
# `--allow-dirty`: `make test` checks the working tree as it is, edits not yet
# committed included (in CI the clone is clean and the flag changes nothing).
# What goes in is decided by `include` in Cargo.toml either way.
#
# Cargo notes every test target it leaves out ("ignoring test `x` as
# `tests/x.rs` is not included in the published package"): tests/ stays in
# the repository on purpose, so those notes are counted, not printed.
log="$target_dir/package-check.log"
mkdir -p "$target_dir"
if ! "$CARGO" package --allow-dirty >"$log" 2>&1; then
    cat "$log" >&2
    fail "cargo package failed (log above)"
fi
ignored_tests=$(grep -c '^warning: ignoring test `.*` as `tests/.*` is not included in the published package$' "$log" || true)
grep -v '^warning: ignoring test `.*` as `tests/.*` is not included in the published package$' "$log" |
    grep -v '^ *Compiling \|^ *Checking ' || true
say "$ignored_tests test targets left out of the package (tests/ is not packaged)"
[ -f "$crate_file" ] || fail "cargo package wrote no $crate_file"

files=$(tar tzf "$crate_file" | grep -vc '/$')
bytes=$(wc -c <"$crate_file")
say "$name-$version.crate: $files files, $bytes bytes"
# What a user needs is in; what only the repository needs is out.
listing=$(tar tzf "$crate_file")
for needed in Cargo.toml Cargo.lock README.md CHANGELOG.md LICENSE-MIT LICENSE-APACHE \
    src/lib.rs src/guide.rs docs/guide/getting_started.md kernels/march.cl kernels/shade.cl \
    kernels/optics.cl kernels/render.cl kernels/eval.cl \
    examples/gallery.rs; do
    grep -qx "$name-$version/$needed" <<<"$listing" || fail "the package lacks $needed"
done
# The guide's chapters are the one part of docs/ the library needs (its
# `guide` module includes them); the pictures stay out.
for unwanted in tests/ docs/ scripts/ .ci/ Makefile; do
    extra=$(grep "^$name-$version/$unwanted" <<<"$listing" | grep -v "^$name-$version/docs/guide/" || true)
    if [ -n "$extra" ]; then
        fail "the package holds $unwanted, which only the repository needs"
    fi
done

# --- 2. A new crate that depends on the package -------------------------------
rm -rf "$work"
mkdir -p "$work/readme-program/src/bin"
tar xzf "$crate_file" -C "$work"
cp "$work/$name-$version/Cargo.lock" "$work/readme-program/Cargo.lock"
awk '
    /<!-- readme-program: start -->/ { inside = 1; next }
    /<!-- readme-program: end -->/ { inside = 0 }
    inside && /^```/ { fence = !fence; next }
    inside && fence { print }
' README.md >"$work/readme-program/src/main.rs"
lines=$(wc -l <"$work/readme-program/src/main.rs")
[ "$lines" -gt 0 ] || fail "no program between the readme-program markers in README.md"
say "the README's program: $lines lines"
rustfmt --edition 2024 --check "$work/readme-program/src/main.rs" ||
    fail "the README's program is not formatted as rustfmt would (diff above)"

# The profile the package declares for its dependencies, copied from its
# Cargo.toml so the ones `cargo package` compiled are reused: the `"*"`
# section, and each named package's where the program depends on it (cargo
# warns of a name it does not find).
profile_section() {
    awk -v want="$1" '
        /^\[profile\.dev\.package\./ {
            name = $0
            sub(/^\[profile\.dev\.package\./, "", name)
            sub(/\]$/, "", name)
            on = (name == want)
            if (on) print
            next
        }
        /^\[/ { on = 0 }
        on && NF && !/^#/
    ' Cargo.toml
}
write_manifest() {
    cat >"$work/readme-program/Cargo.toml" <<EOF
[package]
name = "readme-program"
version = "0.0.0"
edition = "2024"
publish = false

[dependencies]
$name = { path = "../$name-$version" }

# Its own workspace, whatever directory it sits in.
[workspace]

# The package's dependency profile (see the script); the library itself
# (compiled again, from the unpacked copy) unoptimised, as \`cargo package\`
# builds it.
$1

[profile.dev.package.$name]
opt-level = 0
EOF
}
dependency_profile=$(profile_section '"*"')
[ -n "$dependency_profile" ] || fail 'Cargo.toml declares no [profile.dev.package."*"]'
write_manifest "$dependency_profile"
present=$(cd "$work/readme-program" &&
    "$CARGO" tree --quiet --prefix none -e normal,build --format '{p}' | cut -d' ' -f1 | sort -u)
for package in $(sed -n 's/^\[profile\.dev\.package\.\([^"]*\)\]$/\1/p' Cargo.toml); do
    if grep -qx "$package" <<<"$present"; then
        dependency_profile+=$'\n'$(profile_section "$package")
    fi
done
write_manifest "$dependency_profile"


cat >"$work/readme-program/src/bin/check_png.rs" <<'EOF'
//! Checks that the PNG the README's program wrote is a picture of
//! something: readable, not tiny, and with the many colours of a shaded
//! surface. An empty view (the sky's gradient alone: about 190 colours at
//! 320x240) or a flat image fails.
use std::collections::HashSet;

fn main() {
    let path = std::env::args().nth(1).expect("usage: check_png FILE");
    let image = fractal_sdf::image::open(&path)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .to_rgba8();
    let (width, height) = image.dimensions();
    assert!(width >= 16 && height >= 16, "{path}: only {width}x{height}");
    let pixels = width as usize * height as usize;
    let colours = image.pixels().map(|p| p.0).collect::<HashSet<_>>().len();
    let needed = (pixels / 100).max(256);
    assert!(
        colours >= needed,
        "{path}: {colours} colours, fewer than {needed}: nothing was drawn"
    );
    println!("{path}: {width}x{height}, {colours} colours (at least {needed} needed)");
}
EOF

# --- 3. Build it, run it, check the picture -----------------------------------
export CARGO_TARGET_DIR="$target_dir"
(
    cd "$work/readme-program"
    "$CARGO" build --bins
    run_dir=$(mktemp -d "$work/run.XXXXXX")
    program="$CARGO_TARGET_DIR/debug/readme-program"
    (cd "$run_dir" && "$program")
    png=$(find "$run_dir" -name '*.png' | head -n 1)
    [ -n "$png" ] || fail "the README's program wrote no PNG"
    "$CARGO_TARGET_DIR/debug/check_png" "$png"
)
say "passed in $(($(date +%s) - start))s"
