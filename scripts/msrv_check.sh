#!/usr/bin/env bash
# The declared minimum Rust version (`rust-version` in Cargo.toml) against
# every package the locked build can use: the library's dependencies with
# every feature on, on every platform, and the dev-dependencies the tests,
# examples and benches use. Fails if any of them declares a higher
# `rust-version`, naming it. Called by scripts/test.sh.
#
# What this does not check: that the crate compiles with that toolchain
# (only one toolchain is installed here), and dependencies that declare no
# `rust-version` at all. Uses of the standard library newer than the
# declared version are caught by clippy's `incompatible_msrv` lint, which
# reads the same field.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
CARGO=${CARGO:-cargo}

command -v jq >/dev/null 2>&1 || {
    echo "msrv-check: jq not found (make setup installs it)" >&2
    exit 1
}

metadata=$("$CARGO" metadata --quiet --format-version 1 --locked --all-features)
ours=$(jq -r --arg root "$PWD/Cargo.toml" \
    '.packages[] | select(.manifest_path == $root) | .rust_version' <<<"$metadata")
if [ -z "$ours" ] || [ "$ours" = null ]; then
    echo "msrv-check: Cargo.toml declares no rust-version" >&2
    exit 1
fi

# "1.85" and "1.85.0" are the same version: compare major.minor.patch.
normalize() {
    local IFS=.
    # shellcheck disable=SC2206 # splitting on dots is the point
    local parts=($1)
    printf '%d.%d.%d' "${parts[0]}" "${parts[1]:-0}" "${parts[2]:-0}"
}
newer() { # whether version $1 is newer than $2
    [ "$(normalize "$1")" != "$(normalize "$2")" ] &&
        [ "$(printf '%s\n%s\n' "$(normalize "$1")" "$(normalize "$2")" | sort -V | tail -n 1)" = "$(normalize "$1")" ]
}

total=0
declared=0
highest=0.0.0
highest_names=""
too_new=()
while read -r name version rust; do
    total=$((total + 1))
    [ "$rust" = null ] && continue
    declared=$((declared + 1))
    if newer "$rust" "$ours"; then
        too_new+=("$name $version needs Rust $rust")
    fi
    if newer "$rust" "$highest"; then
        highest=$rust
        highest_names="$name $version"
    elif [ "$(normalize "$rust")" = "$(normalize "$highest")" ]; then
        highest_names="$highest_names, $name $version"
    fi
done < <(jq -r --arg root "$PWD/Cargo.toml" \
    '.packages[] | select(.manifest_path != $root) | "\(.name) \(.version) \(.rust_version)"' \
    <<<"$metadata")

printf 'msrv-check: rust-version %s; %d locked packages, %d declare a rust-version, the highest %s (%s)\n' \
    "$ours" "$total" "$declared" "$highest" "$highest_names"
if ((${#too_new[@]} > 0)); then
    printf 'msrv-check: these need a newer Rust than rust-version = "%s" in Cargo.toml:\n' "$ours" >&2
    printf '  %s\n' "${too_new[@]}" >&2
    exit 1
fi
