#!/usr/bin/env bash
# Renders a short sequence on a real (one-node, localhost) Slurm cluster
# with deploy/slurm/, cancelling one array task half-way and resubmitting
# it, and checks the frames against a single process's, byte for byte.
#
# Usage:
#   scripts/slurm-test.sh [FRACTAL_SDF [SCENE]]
#
#   FRACTAL_SDF  the fractal-sdf binary (default: $FRACTAL_SDF, else
#                `fractal-sdf` on the PATH)
#   SCENE        a scene file (.ron) or gallery name (default: fractal_mix)
#
# Environment:
#   CI=true              failing to install or start Slurm fails the test;
#                        elsewhere it is skipped (a SKIP line, exit 0, and a
#                        line in target/tmp/skipped.txt)
#   SLURM_TEST_PRESET    a --preset for every render (default: the binary's)
#   SLURM_TEST_TIMEOUT   seconds any one wait may last (default: 300)
#   SLURM_STATE_DIR      the cluster's state directory (see scripts/slurm.sh)
#
# What it does, 24 frames at 96x64 and 24 fps, in a fresh directory under
# target/:
#   1. starts the cluster with scripts/slurm.sh (installing slurm-wlm and
#      munge first if they are missing; stopped again on exit, unless it
#      was already running);
#   2. renders the frames in one process (`fractal-sdf sequence`, no
#      --shard): the reference, timed;
#   3. submits the 4-task array and its encode job (deploy/slurm/submit.sh),
#      timed, and checks the encode job started after the last task ended;
#   4. submits them again, into another directory; one task is paused
#      (SIGSTOP) right after its first frame and cancelled with
#      `scancel JOB_TASK` while the others finish; the encode job must then
#      wait (DependencyNeverSatisfied); the task is resubmitted alone
#      (`sbatch --array=TASK`, SHARDS=4), the encode job pointed at it
#      (`scontrol update Dependency=afterok:NEW`), and must run after it;
#   5. checks both arrays' frames with `fractal-sdf sequence --verify` and
#      compares every frame with the reference's (`cmp`).
# It prints the wall time of the cluster's start, of the single process and
# of the 4-task array.
#
# The pause in step 4 comes from a wrapper around the binary that the
# array's tasks run: it passes every argument through unchanged, and only
# in the chosen task stops the binary once a frame of its shard is on disk,
# so the cancel lands half-way however fast frames render.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"

FPS=24
FRAMES=0..24
NFRAMES=24
SIZE=96x64
TASKS=4
PAUSE_TASK=1
per_task=$((NFRAMES / TASKS))
wait_timeout=${SLURM_TEST_TIMEOUT:-300}
preset=${SLURM_TEST_PRESET:-}

say() { printf 'slurm-test: %s\n' "$*"; }
err() { printf 'slurm-test: %s\n' "$*" >&2; }

ci=false
[[ "${CI:-}" == true || "${CI:-}" == 1 ]] && ci=true

# --- Arguments ----------------------------------------------------------------
bin=${1:-${FRACTAL_SDF:-}}
if [[ -z "$bin" ]]; then
    bin=$(command -v fractal-sdf || true)
    [[ -n "$bin" ]] || {
        err "no fractal-sdf binary: pass its path as \$1 or FRACTAL_SDF"
        exit 2
    }
fi
[[ "$bin" == */* ]] && bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
[[ -x "$bin" ]] || {
    err "not an executable: $bin"
    exit 2
}
scene=${2:-fractal_mix}
[[ -f "$scene" ]] && scene=$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")

# --- State, cleanup, failure -------------------------------------------------
state=${SLURM_STATE_DIR:-$repo/target/slurm}
export SLURM_STATE_DIR=$state
export SLURM_CONF=$state/slurm.conf
work=""
started_cluster=false
our_jobs=()
ok=false

cleanup() {
    local rc=$?
    if ((${#our_jobs[@]})); then
        timeout 20 scancel --full "${our_jobs[@]}" 2>/dev/null || true
    fi
    if $started_cluster; then
        bash "$repo/scripts/slurm.sh" stop >&2 || err "stopping the cluster failed"
    fi
    if [[ -n "$work" ]]; then
        if $ok; then
            rm -rf "$work"
        else
            err "files kept for inspection in $work"
        fi
    fi
    exit "$rc"
}
trap cleanup EXIT

# The tails of the daemons' logs and of the jobs' outputs.
log_tails() {
    local f files=("$state"/log/*.log)
    [[ -n "$work" ]] && files+=("$work"/*.log "$work"/*-logs/*.out)
    for f in "${files[@]}"; do
        [[ -s "$f" ]] || continue
        printf '\n----- %s (last 20 lines) -----\n' "$f" >&2
        tail -n 20 "$f" >&2
    done
}

fail() {
    err "FAIL: $*"
    log_tails
    exit 1
}

# --- Skipping ------------------------------------------------------------------
# Without Slurm (not root, packages not installable, daemons not starting)
# the test is skipped, except in CI, where that is a failure.
skip_or_fail() {
    if $ci; then
        fail "$*"
    fi
    say "SKIP: $*"
    mkdir -p "$repo/target/tmp"
    printf 'slurm-test: Slurm job array on localhost: %s\n' "$*" >>"$repo/target/tmp/skipped.txt"
    exit 0
}

have_slurm() {
    local tool
    for tool in munged mungekey slurmctld slurmd sbatch squeue scancel scontrol sinfo; do
        command -v "$tool" >/dev/null 2>&1 || return 1
    done
}

if [[ $(id -u) -ne 0 ]]; then
    skip_or_fail "needs root (the cluster's daemons run as root)"
fi
if ! have_slurm; then
    say "installing slurm-wlm and munge"
    if ! command -v apt-get >/dev/null 2>&1; then
        skip_or_fail "slurm-wlm and munge are not installed, and there is no apt-get"
    fi
    if ! timeout 900 bash -c 'apt-get -o DPkg::Lock::Timeout=600 update -qq &&
        DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 \
            install -y -qq --no-install-recommends slurm-wlm munge' >&2 || ! have_slurm; then
        skip_or_fail "could not install slurm-wlm and munge"
    fi
fi

# --- The cluster -------------------------------------------------------------
if bash scripts/slurm.sh status >/dev/null 2>&1; then
    say "using the cluster already running in $state"
    cluster_s=0
else
    started_cluster=true
    t0=$(date +%s%N)
    if ! timeout 120 bash scripts/slurm.sh start; then
        skip_or_fail "could not start the one-node Slurm cluster (scripts/slurm.sh start; logs in $state/log)"
    fi
    ds=$((($(date +%s%N) - t0) / 100000000))
    cluster_s=$((ds / 10)).$((ds % 10))
    say "cluster started in ${cluster_s}s"
fi
work=$(mktemp -d "$repo/target/slurm-test.XXXXXX")

# --- Helpers -------------------------------------------------------------------
# Nanoseconds since the epoch, and the seconds since such a time (0.1 s).
now_ns() { date +%s%N; }
elapsed() {
    local ds=$((($(now_ns) - $1) / 100000000))
    printf '%d.%d' $((ds / 10)) $((ds % 10))
}

# wait_until DESCRIPTION COMMAND...: polls COMMAND until it succeeds, for
# at most SLURM_TEST_TIMEOUT seconds.
wait_until() {
    local what=$1 deadline=$((SECONDS + wait_timeout))
    shift
    until "$@"; do
        ((SECONDS < deadline)) || fail "timed out after ${wait_timeout}s waiting for $what"
        sleep 0.2
    done
}

# Whether none of the jobs (comma-separated ids) is pending or running.
jobs_done() {
    local out
    out=$(timeout 20 squeue --noheader --jobs="$1" --format=%i \
        --states=PENDING,RUNNING,CONFIGURING,COMPLETING,SUSPENDED,REQUEUED) ||
        fail "squeue failed"
    [[ -z "$out" ]]
}

# job_field JOB FIELD: one field of `scontrol show job` (JOB may be ID_TASK).
job_field() {
    timeout 20 scontrol --oneliner show job "$1" | tr ' ' '\n' | sed -n "s/^$2=//p" | head -n 1
}

epoch() { date -d "$1" +%s; }

# shard_frames TASK: the frame files of shard TASK in FRAMES (0..24).
shard_frames() {
    local i
    for ((i = $1; i < NFRAMES; i += TASKS)); do
        printf 'frame_%05d.png\n' "$i"
    done
}

# count_shard DIR TASK: how many of shard TASK's frames are in DIR.
count_shard() {
    local f n=0
    for f in $(shard_frames "$2"); do
        [[ -f "$1/$f" ]] && n=$((n + 1))
    done
    echo "$n"
}

sequence_args() {
    # The options every render of this test shares.
    local args=(sequence "$scene" --fps "$FPS" --size "$SIZE")
    [[ -n "$preset" ]] && args+=(--preset "$preset")
    printf '%s\n' "${args[@]}"
}
mapfile -t common < <(sequence_args)

# check_encode ENCODE_JOB JOB...: the encode job completed and started after
# every one of JOB's tasks ended.
check_encode() {
    local encode=$1 job start end task_end latest=0
    shift
    [[ "$(job_field "$encode" JobState)" == COMPLETED ]] ||
        fail "encode job $encode: $(job_field "$encode" JobState), not COMPLETED"
    start=$(epoch "$(job_field "$encode" StartTime)")
    for job in "$@"; do
        # Each task's record: `scontrol show job ARRAY` lists them all.
        while read -r task_end; do
            end=$(epoch "$task_end")
            ((end > latest)) && latest=$end
        done < <(timeout 20 scontrol --oneliner show job "$job" | tr ' ' '\n' | sed -n 's/^EndTime=//p')
    done
    ((start >= latest)) ||
        fail "encode job $encode started at $start, before the array's last task ended ($latest)"
    grep -q 'all frames present' "$work"/*-logs/encode-"$encode".out ||
        fail "encode job $encode did not report the frames complete"
    say "encode job $encode ran after the array (started $((start - latest))s after its last task ended)"
}

# --- 1. The reference: one process -------------------------------------------
say "binary: $bin; scene: $scene; $NFRAMES frames at $SIZE, $TASKS tasks; work dir $work"
# A first frame, untimed: the OpenCL platform's kernel cache is warm for
# both timings below.
timeout "$wait_timeout" "$bin" "${common[@]}" --frames 0..1 --out "$work/warmup" --no-video \
    >"$work/warmup.log" 2>&1 || fail "fractal-sdf could not render a first frame"
t0=$(now_ns)
timeout "$wait_timeout" "$bin" "${common[@]}" --frames "$FRAMES" --out "$work/single" --no-video \
    >"$work/single.log" 2>&1 || fail "the single-process render failed"
single_s=$(elapsed "$t0")
say "single process: $NFRAMES frames in ${single_s}s"

# --- 2. The array, timed -------------------------------------------------------
submit() { # submit OUT FRACTAL_SDF: eval-able array_job= / encode_job= lines
    FRACTAL_SDF=$2 SCENE=$scene FPS=$FPS FRAMES=$FRAMES SIZE=$SIZE TASKS=$TASKS \
        OUT=$1 PRESET=$preset LOG_DIR=$1-logs \
        timeout 60 bash deploy/slurm/submit.sh || fail "submit.sh failed"
}
t0=$(now_ns)
eval "$(submit "$work/array" "$bin")"
our_jobs+=("$array_job" "$encode_job")
wait_until "array job $array_job" jobs_done "$array_job"
array_s=$(elapsed "$t0")
for ((t = 0; t < TASKS; t++)); do
    s=$(job_field "${array_job}_$t" JobState)
    [[ "$s" == COMPLETED ]] || fail "task ${array_job}_$t: $s"
done
say "array of $TASKS tasks: $NFRAMES frames in ${array_s}s (submission to last task's end)"
wait_until "encode job $encode_job" jobs_done "$encode_job"
check_encode "$encode_job" "$array_job"

# --- 3. Cancel a task half-way, resubmit it ----------------------------------
# The wrapper the tasks run: the binary, paused after the first frame of
# shard PAUSE_TASK's first run.
wrapper=$work/pausing-fractal-sdf
cat >"$wrapper" <<EOF
#!/usr/bin/env bash
# Runs $bin with the same arguments. In array task $PAUSE_TASK, while
# $work/pause-task exists (once), stops it (SIGSTOP) when a frame of its
# shard is on disk, and writes that shard's frame count to $work/paused.
set -euo pipefail
"$bin" "\$@" &
pid=\$!
if [[ "\${SLURM_ARRAY_TASK_ID:-}" == $PAUSE_TASK ]] && rm "$work/pause-task" 2>/dev/null; then
    while kill -0 "\$pid" 2>/dev/null; do
        n=0
        for f in $(shard_frames "$PAUSE_TASK" | tr '\n' ' '); do
            [[ -f "$work/resumed/\$f" ]] && n=\$((n + 1))
        done
        if ((n > 0)); then
            kill -STOP "\$pid"
            echo "\$n" >"$work/paused.tmp"
            mv "$work/paused.tmp" "$work/paused"
            break
        fi
        sleep 0.01
    done
fi
wait "\$pid"
EOF
chmod +x "$wrapper"
touch "$work/pause-task"

eval "$(submit "$work/resumed" "$wrapper")"
our_jobs+=("$array_job" "$encode_job")
task=${array_job}_$PAUSE_TASK
wait_until "task $task to render its first frame" test -s "$work/paused"
written=$(<"$work/paused")
((written < per_task)) ||
    fail "task $task had written all its $per_task frames before it could be paused"
[[ "$(job_field "$task" JobState)" == RUNNING ]] || fail "task $task is not running"
say "task $task paused with $written of $per_task frames written; cancelling it"
timeout 20 scancel "$task" || fail "scancel $task failed"
wait_until "array job $array_job" jobs_done "$array_job"
s=$(job_field "$task" JobState)
[[ "$s" == CANCELLED ]] || fail "task $task: $s, not CANCELLED"
for ((t = 0; t < TASKS; t++)); do
    ((t == PAUSE_TASK)) && continue
    s=$(job_field "${array_job}_$t" JobState)
    [[ "$s" == COMPLETED ]] || fail "task ${array_job}_$t: $s"
done
left=$(count_shard "$work/resumed" "$PAUSE_TASK")
((left == written)) || fail "task $task wrote frames after it was cancelled ($written, then $left)"
# The frames it wrote, by inode and time: a resumed run must keep them.
kept_frames() {
    local f
    for f in $(shard_frames "$PAUSE_TASK"); do
        [[ -f "$work/resumed/$f" ]] || continue
        stat -c '%n %i %y' "$work/resumed/$f"
    done
}
kept=$(kept_frames)

# The encode job must not run after a cancelled task.
reason() { [[ "$(job_field "$encode_job" Reason)" == DependencyNeverSatisfied ]]; }
wait_until "encode job $encode_job to report DependencyNeverSatisfied" reason
[[ "$(job_field "$encode_job" JobState)" == PENDING ]] ||
    fail "encode job $encode_job is $(job_field "$encode_job" JobState), not PENDING"
say "encode job $encode_job waits (DependencyNeverSatisfied), as it should"

# Resubmit the cancelled task alone; it renders only the frames it lacks.
resubmitted=$(FRACTAL_SDF=$wrapper SCENE=$scene FPS=$FPS FRAMES=$FRAMES SIZE=$SIZE \
    OUT=$work/resumed PRESET=$preset SHARDS=$TASKS \
    timeout 60 sbatch --parsable --export=ALL --array="$PAUSE_TASK" \
    --output="$work/resumed-logs/render-%A_%a.out" deploy/slurm/render-array.sbatch) ||
    fail "resubmitting task $PAUSE_TASK failed"
resubmitted=${resubmitted%%;*}
our_jobs+=("$resubmitted")
timeout 20 scontrol update JobId="$encode_job" Dependency="afterok:$resubmitted" ||
    fail "could not point encode job $encode_job at job $resubmitted"
say "resubmitted task $PAUSE_TASK as job $resubmitted; encode job $encode_job now waits for it"
wait_until "job $resubmitted and encode job $encode_job" jobs_done "$resubmitted,$encode_job"
s=$(job_field "${resubmitted}_$PAUSE_TASK" JobState)
[[ "$s" == COMPLETED ]] || fail "resubmitted task ${resubmitted}_$PAUSE_TASK: $s"
check_encode "$encode_job" "$array_job" "$resubmitted"
while read -r f inode mtime; do
    [[ "$(stat -c '%i %y' "$f")" == "$inode $mtime" ]] ||
        fail "the resubmitted task rendered $f again instead of keeping it"
done <<<"$kept"
say "the resubmitted task kept the $written frame(s) on disk and rendered the other $((per_task - written))"

# --- 4. The frames -------------------------------------------------------------
for dir in array resumed; do
    timeout "$wait_timeout" "$bin" "${common[@]}" --frames "$FRAMES" --out "$work/$dir" --verify ||
        fail "fractal-sdf --verify failed on the $dir frames"
done
mismatches=0
for ((i = 0; i < NFRAMES; i++)); do
    f=$(printf 'frame_%05d.png' "$i")
    for dir in array resumed; do
        if ! cmp -s "$work/single/$f" "$work/$dir/$f"; then
            err "$dir/$f differs from the single process's"
            mismatches=$((mismatches + 1))
        fi
    done
done
((mismatches == 0)) || fail "$mismatches frames differ from the single process's"
say "all $NFRAMES frames valid, and equal byte for byte, in both arrays and the single process"

ok=true
say "timings: cluster start ${cluster_s}s; single process ${single_s}s; $TASKS-task array ${array_s}s ($NFRAMES frames at $SIZE)"
say "PASS"
