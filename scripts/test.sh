#!/usr/bin/env bash
# The full check run by `make test` (and CI): format, the minimum Rust
# version, lints, tests, docs, and the crate as packaged for crates.io.
# Prints a header per step and the total wall time at the end.
#
# The tests use every feature (`--all-features`: the viewer's window and
# the `proptest` testing toolkit, which the property tests require), so the
# crate is compiled once per mode; two cheap checks (no code generation)
# cover the default features and each feature alone.
set -euo pipefail

CARGO=${CARGO:-cargo}
start=$(date +%s)

# Each step's wall time, for the summary at the end.
timings=()
step() {
    printf '\n==> %s\n' "$*"
    local began=$SECONDS
    "$@"
    timings+=("$(printf '%5ss  %s' "$((SECONDS - began))" "$*")")
}

# CI builds from a clean clone: incremental compilation's caches would cost
# time to write and never be read.
if [ "${CI:-}" = true ]; then
    export CARGO_INCREMENTAL=0
fi

# The tests must find PoCL (installed by `make setup`) with fp64: a
# missing device fails them instead of skipping them.
export FRACTAL_SDF_REQUIRE_DEVICE=1
skipped=target/tmp/skipped.txt
rm -f "$skipped"

# Property tests draw their cases from a fixed seed here, so a failure
# reproduces exactly: rerun with the seed printed below. Failing cases are
# also kept in tests/SUITE/*.proptest-regressions and tried first on every run.
export PROPTEST_RNG_SEED=${PROPTEST_RNG_SEED:-20261201}
printf '==> proptest seed: PROPTEST_RNG_SEED=%s\n' "$PROPTEST_RNG_SEED"

step "$CARGO" fmt --all -- --check
# Every locked dependency's rust-version against ours (Cargo.toml).
step bash scripts/msrv_check.sh
step "$CARGO" clippy --all-targets --all-features -- -D warnings
# What a contributor's plain `cargo test` builds, and every feature alone
# and none at all: a target that needs a feature without saying so
# (`required-features`), or code that compiles only with everything on,
# fails here, and so does a warning that only one of them shows. Checks
# only: no code generation. (The library and the command check with exactly
# the features asked: dev-dependencies add features only to the targets
# that use them.)
step "$CARGO" check --all-targets
step "$CARGO" hack clippy --each-feature -- -D warnings
# The binaries tests/viewer_smoke.rs runs (`cargo test` builds examples only as
# test harnesses); the test profile shares the library build with the tests.
step "$CARGO" build --profile test --all-features --example viewer --example wgpu_window
step "$CARGO" test --all-targets --all-features
step "$CARGO" test --doc --all-features
# The features docs.rs documents (`[package.metadata.docs.rs]`: all of them).
# Its `--cfg docsrs` needs a nightly rustdoc, so it is left out here.
RUSTDOCFLAGS="-D warnings" step "$CARGO" doc --no-deps --all-features
# The `fractal-sdf` command renders a sequence as a job array on a one-node
# Slurm cluster started here (`cargo test` built the binary above).
step bash scripts/slurm-test.sh target/debug/fractal-sdf
# The crate as published: built from its package, and the README's program
# run against that package on the device.
step bash scripts/package_check.sh

if [ -s "$skipped" ]; then
    printf '\n==> checks skipped (see above):\n'
    cat "$skipped"
fi
printf '\n==> time per step:\n'
printf '%s\n' "${timings[@]}"
printf '\n==> make test: all steps passed in %ss\n' "$(($(date +%s) - start))"
