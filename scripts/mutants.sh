#!/usr/bin/env bash
# `make mutants`: how many deliberate bugs the tests catch (the guide, "How
# it is tested"). Not part of `make test`.
#
#   Rust: cargo-mutants over src/cpu, src/ir, src/codegen and src/testing
#         (.cargo/mutants.toml), each mutant judged by the test suites that
#         exercise that code. Every mutant takes a rebuild, so by default one
#         round-robin shard of 20 (every 20th mutant, spread over every
#         file) runs: MUTANTS_SHARD=0/20. MUTANTS_SHARD=all runs them all.
#   Kernels: scripts/mutate_kernels.py, KERNEL_SAMPLE mutants (default 60;
#         "all" for every one) spread evenly over kernels/.
#
# Results: target/mutants/mutants.out (caught.txt, missed.txt, timeout.txt,
# unviable.txt) and target/mutants-kernels/results.json.
set -euo pipefail

CARGO=${CARGO:-cargo}
MUTANTS_SHARD=${MUTANTS_SHARD:-0/20}
KERNEL_SAMPLE=${KERNEL_SAMPLE:-60}
export FRACTAL_SDF_REQUIRE_DEVICE=1
export PROPTEST_RNG_SEED=${PROPTEST_RNG_SEED:-20261201}

if ! "$CARGO" mutants --version >/dev/null 2>&1; then
    printf '==> installing cargo-mutants\n'
    "$CARGO" install cargo-mutants --locked --version 27.1.0
fi

shard=()
if [ "$MUTANTS_SHARD" != all ]; then
    shard=(--shard "$MUTANTS_SHARD" --sharding round-robin)
fi
printf '==> Rust mutants (%s)\n' "$MUTANTS_SHARD"
# cargo-mutants exits non-zero when a mutant survives; the summary says how
# many, and the kernel run still happens.
rust=0
"$CARGO" mutants "${shard[@]}" --output target/mutants --timeout 300 || rust=$?

printf '\n==> kernel mutants (%s)\n' "$KERNEL_SAMPLE"
if [ "$KERNEL_SAMPLE" = all ]; then
    python3 scripts/mutate_kernels.py --all
else
    python3 scripts/mutate_kernels.py --sample "$KERNEL_SAMPLE"
fi
printf '\n==> Rust mutants: exit %s (2: some survived; see target/mutants/mutants.out/missed.txt)\n' "$rust"
