#!/usr/bin/env bash
# Submits a frame sequence to Slurm: a job array that renders it in TASKS
# shards (render-array.sbatch), then the encode job (encode.sbatch), which
# waits for every array task to succeed (--dependency=afterok:<array>).
#
# Usage:
#   [VAR=value ...] deploy/slurm/submit.sh [SBATCH_OPTION ...]
#
#   SCENE=fractal_mix FPS=24 FRAMES=0..240 SIZE=1920x1080 TASKS=8 \
#     OUT=/shared/frames/mix deploy/slurm/submit.sh --partition=gpu --gres=gpu:1
#
# SBATCH_OPTIONs (partition, time, account, gres, ...) are passed to both
# sbatch calls; #SBATCH lines in the two scripts hold the defaults.
#
# Parameters (environment):
#   TASKS        array tasks, i.e. shards (default: 4)
#   FRACTAL_SDF  the fractal-sdf binary the jobs run (default: `fractal-sdf`
#                on the compute nodes' PATH; a path is made absolute)
#   SCENE        scene file (.ron; made absolute) or gallery name (default: fractal_mix)
#   FPS          frames per second (default: 24)
#   FRAMES       range `a..b` (default: the whole sequence)
#   SIZE         WIDTHxHEIGHT (default: 640x480)
#   OUT          frames directory on a file system the nodes share
#                (default: out/<scene name>; made absolute)
#   PRESET       quality preset (default: the binary's own)
#   DURATION     sequence length in seconds (default: the binary's own)
#   VIDEO        the encoded video (default: <OUT>.mp4)
#   LOG_DIR      the jobs' output files (default: <OUT>-logs)
#
# Prints, on stdout, `array_job=<id>` and `encode_job=<id>` (lines a shell
# can eval); on stderr, how to follow and repair the run.
#
# If a task fails or is cancelled, the encode job stays pending for ever
# (reason DependencyNeverSatisfied). Resubmit that task alone, then point
# the encode job at the new job:
#   SHARDS=<TASKS> <the same variables> sbatch --parsable --array=<task> deploy/slurm/render-array.sbatch
#   scontrol update JobId=<encode job> Dependency=afterok:<new job>
# The task skips the frames already on disk.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

TASKS=${TASKS:-4}
FRACTAL_SDF=${FRACTAL_SDF:-fractal-sdf}
SCENE=${SCENE:-fractal_mix}
FPS=${FPS:-24}
FRAMES=${FRAMES:-}
SIZE=${SIZE:-640x480}
scene_name=$(basename "$SCENE" .ron)
OUT=${OUT:-out/$scene_name}
PRESET=${PRESET:-}
DURATION=${DURATION:-}

if ! [[ "$TASKS" =~ ^[1-9][0-9]*$ ]]; then
    echo "submit.sh: TASKS must be a positive integer, got '$TASKS'" >&2
    exit 2
fi
command -v sbatch >/dev/null 2>&1 || {
    echo "submit.sh: sbatch not found: run this on a Slurm login node" >&2
    exit 2
}

# The jobs start elsewhere, in the submission directory: absolute paths.
absolute() { [[ "$1" == /* ]] && printf '%s\n' "$1" || printf '%s\n' "$PWD/$1"; }
[[ "$FRACTAL_SDF" == */* ]] && FRACTAL_SDF=$(absolute "$FRACTAL_SDF")
[[ -f "$SCENE" ]] && SCENE=$(absolute "$SCENE")
OUT=$(absolute "${OUT%/}")
VIDEO=$(absolute "${VIDEO:-$OUT.mp4}")
LOG_DIR=$(absolute "${LOG_DIR:-$OUT-logs}")
SHARDS=$TASKS
mkdir -p "$OUT" "$LOG_DIR"
export FRACTAL_SDF SCENE FPS FRAMES SIZE OUT PRESET DURATION VIDEO SHARDS

# --parsable prints `<id>` or `<id>;<cluster>`.
array_job=$(sbatch --parsable --export=ALL --array="0-$((TASKS - 1))" \
    --output="$LOG_DIR/render-%A_%a.out" "$@" "$here/render-array.sbatch")
array_job=${array_job%%;*}
encode_job=$(sbatch --parsable --export=ALL --dependency="afterok:$array_job" \
    --output="$LOG_DIR/encode-%j.out" "$@" "$here/encode.sbatch")
encode_job=${encode_job%%;*}

echo "array_job=$array_job"
echo "encode_job=$encode_job"
cat >&2 <<MSG
submit.sh: render array $array_job (tasks 0-$((TASKS - 1))) -> $OUT
submit.sh: encode job $encode_job runs after every task succeeds -> $VIDEO
submit.sh: follow with: squeue -j $array_job,$encode_job; logs in $LOG_DIR
MSG
