#!/usr/bin/env bash
# The full check run by `make test` (and CI): format, lints, tests, docs.
# Prints a header per step and the total wall time at the end.
set -euo pipefail

CARGO=${CARGO:-cargo}
start=$(date +%s)

step() {
    printf '\n==> %s\n' "$*"
    "$@"
}

step "$CARGO" fmt --all -- --check
step "$CARGO" clippy --all-targets -- -D warnings
step "$CARGO" test --all-targets
step "$CARGO" test --doc
RUSTDOCFLAGS="-D warnings" step "$CARGO" doc --no-deps

printf '\n==> make test: all steps passed in %ss\n' "$(($(date +%s) - start))"
