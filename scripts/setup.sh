#!/usr/bin/env bash
# Make sure the system packages fractal-sdf needs are installed (Debian/Ubuntu).
#
# Cheap when everything is present: one dpkg-query call, then exit 0.
# Called by `make setup` (and therefore by `make demo` / `make test`).
set -euo pipefail

# System packages the project needs. Add new ones here, in one place.
REQUIRED_PACKAGES=(
    ocl-icd-opencl-dev # OpenCL ICD loader + headers (libOpenCL.so for the ocl crate)
    pocl-opencl-icd    # PoCL: a CPU OpenCL implementation, so no GPU is required
    clinfo             # lists OpenCL platforms/devices; used for the check below
    pkg-config
    python3            # scripts/mutate_kernels.py (`make mutants`)
    jq                 # reads `cargo metadata` in scripts/msrv_check.sh
    openimageio-tools  # oiiotool: reads the OpenEXR files the tests write, independently
    mesa-vulkan-drivers # lavapipe: a CPU Vulkan driver, on which the WGSL tests run through wgpu
    # The one-node Slurm cluster of scripts/slurm.sh and scripts/slurm-test.sh:
    slurm-wlm          # slurmctld, slurmd and the client commands (sbatch, squeue, ...)
    munge              # munged: the authentication Slurm's daemons and clients use
    # The viewer example's window (feature `viewer`) and its smoke test:
    xvfb               # a virtual X server, so the viewer runs without a display
    xdotool            # sends real key presses to the viewer's window
    libx11-6           # X11 client libraries winit and softbuffer load at run time
    libx11-xcb1
    libxcursor1
    libxrandr2
    libxi6
    libxkbcommon-x11-0
)

say() { printf 'setup: %s\n' "$*"; }
err() { printf 'setup: %s\n' "$*" >&2; }

# --- Rust toolchain -----------------------------------------------------------
if ! command -v cargo >/dev/null 2>&1; then
    err "cargo not found on PATH. Install Rust with rustup:"
    err "  curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh"
    err "then open a new shell (or run: . \"\$HOME/.cargo/env\")."
    exit 1
fi

# --- System packages ----------------------------------------------------------
if ! command -v dpkg-query >/dev/null 2>&1; then
    err "dpkg-query not found: this script supports Debian/Ubuntu only."
    err "Install by hand: an OpenCL ICD loader, an OpenCL platform (e.g. PoCL), clinfo, pkg-config, jq."
    exit 1
fi

# --- Cargo tools ----------------------------------------------------------------
# cargo-hack checks every feature on its own (scripts/test.sh). Built from
# crates.io once; `--locked` uses the versions its authors tested.
CARGO_HACK_VERSION=0.6.46
if ! cargo hack --version >/dev/null 2>&1; then
    say "installing cargo-hack $CARGO_HACK_VERSION (cargo install)"
    cargo install --locked --quiet cargo-hack --version "$CARGO_HACK_VERSION"
fi

missing=()
for pkg in "${REQUIRED_PACKAGES[@]}"; do
    status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
    if [[ "$status" != "install ok installed" ]]; then
        missing+=("$pkg")
    fi
done

if ((${#missing[@]} == 0)); then
    exit 0
fi

say "missing packages: ${missing[*]}"

# Wait up to 10 minutes if another apt/dpkg process holds the lock.
apt_opts=(-o DPkg::Lock::Timeout=600)
if [[ $(id -u) -eq 0 ]]; then
    sudo_cmd=()
elif command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
else
    err "not root and sudo is not available. Run as root:"
    err "  apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends ${missing[*]}"
    exit 1
fi

# apt 2.6 ignores DPkg::Lock::Timeout for the lists lock taken by `update`,
# so retry that step ourselves (up to 10 minutes) while another apt runs.
tries=0
until "${sudo_cmd[@]}" apt-get "${apt_opts[@]}" update; do
    tries=$((tries + 1))
    if ((tries >= 60)); then
        err "apt-get update kept failing (apt lock held for 10 minutes?)"
        exit 1
    fi
    say "apt-get update failed; retrying in 10s (another apt process may hold the lock)"
    sleep 10
done
"${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get "${apt_opts[@]}" install -y --no-install-recommends "${missing[@]}"

# --- OpenCL platform check ----------------------------------------------------
platforms=$(clinfo -l 2>/dev/null | grep -c 'Platform #' || true)
if [[ "$platforms" -eq 0 ]]; then
    err "no OpenCL platform found after installing packages (clinfo -l lists none)."
    err "Check that /etc/OpenCL/vendors/ contains an .icd file (pocl-opencl-icd installs pocl.icd)."
    exit 1
fi
say "OpenCL platforms found: $platforms"
clinfo -l
