#!/usr/bin/env bash
# Times two builds of the `fractal-sdf` command on the same scenes in the
# same run, alternating (old, new, old, new, ...), and prints a Markdown
# table: the median ms/frame of each over the runs, the distance
# evaluations per pixel of each (deterministic), and the PSNR between their
# images.
#
#   scripts/compare-builds.sh OLD_BINARY NEW_BINARY [SCENE ...]
#
# Environment: RUNS (default 3), SIZE (default 640x480), PRESET (default:
# each scene file's own quality), OUT (default target/compare-builds).
set -euo pipefail

if [ $# -lt 2 ]; then
    echo "usage: $0 OLD_BINARY NEW_BINARY [SCENE ...]" >&2
    exit 2
fi
old=$1
new=$2
shift 2
scenes=("$@")
if [ ${#scenes[@]} -eq 0 ]; then
    scenes=(mandelbulb menger julia sierpinski csg primitives domain_ops fractal_mix benchmark)
fi
runs=${RUNS:-3}
size=${SIZE:-640x480}
out=${OUT:-target/compare-builds}
mkdir -p "$out"
preset=()
if [ -n "${PRESET:-}" ]; then
    preset=(--preset "$PRESET")
fi

# One timed frame after the warm-up (which also counts evaluations).
bench() {
    "$1" bench "$2" --size "$size" --frames 1 "${preset[@]}" | tail -n 1
}
ms() { sed -E 's/^ *([0-9.]+) ms.*/\1/'; }
evals() { sed -E 's/.*; ([0-9.]+) distance.*/\1/'; }
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

echo "| scene | old ms | new ms | speed-up | old evals/px | new evals/px | PSNR new vs old |"
echo "|---|---:|---:|---:|---:|---:|---:|"
total_old=0
total_new=0
for scene in "${scenes[@]}"; do
    : >"$out/$scene.old"
    : >"$out/$scene.new"
    for _ in $(seq "$runs"); do
        bench "$old" "$scene" >>"$out/$scene.old"
        bench "$new" "$scene" >>"$out/$scene.new"
    done
    old_ms=$(ms <"$out/$scene.old" | median)
    new_ms=$(ms <"$out/$scene.new" | median)
    old_ev=$(head -n 1 "$out/$scene.old" | evals)
    new_ev=$(head -n 1 "$out/$scene.new" | evals)
    "$old" render "$scene" --size "$size" "${preset[@]}" -o "$out/$scene-old.png" >/dev/null
    "$new" render "$scene" --size "$size" "${preset[@]}" -o "$out/$scene-new.png" >/dev/null
    psnr=$("$new" compare "$out/$scene-old.png" "$out/$scene-new.png" | sed -E 's/^PSNR ([^ ]+) dB.*/\1/')
    speedup=$(awk -v a="$old_ms" -v b="$new_ms" 'BEGIN { printf "%.2f", a / b }')
    total_old=$(awk -v a="$total_old" -v b="$old_ms" 'BEGIN { print a + b }')
    total_new=$(awk -v a="$total_new" -v b="$new_ms" 'BEGIN { print a + b }')
    echo "| $scene | $old_ms | $new_ms | ${speedup}× | $old_ev | $new_ev | $psnr dB |"
done
echo "| **total** | $total_old | $total_new | $(awk -v a="$total_old" -v b="$total_new" 'BEGIN { printf "%.2f", a / b }')× | | | |"
