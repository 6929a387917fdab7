#!/usr/bin/env bash
# Draws the mesh pictures in `docs/` from written mesh files with an
# independent renderer, Debian's `f3d` (installed here if it is missing),
# headless under Xvfb:
#
#   docs/mesh-menger.png   a level-4 Menger sponge, `fractal-sdf mesh`, 256 cells across
#   docs/mesh-mandelbulb.png  the gallery's Mandelbulb as coloured PLY, 256 cells across
#
#   scripts/mesh-pictures.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v f3d >/dev/null || ! command -v xvfb-run >/dev/null; then
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get install -y f3d xvfb
fi

cargo build --release --features cli --bin fractal-sdf
out=target/mesh-pictures
mkdir -p "$out" docs
bin=target/release/fractal-sdf
cat > "$out/sponge.ron" <<'RON'
(
    version: 1,
    geometry: Color(
        color: (0.85, 0.85, 0.8),
        child: Menger(iterations: 4, scale: 3.0),
    ),
)
RON
"$bin" mesh "$out/sponge.ron" -o "$out/menger.stl" --resolution 256
"$bin" mesh mandelbulb -o "$out/mandelbulb.ply" --resolution 256

draw() {
    xvfb-run -a f3d "$1" --output="$2" --resolution=640,480 --ssao --fxaa \
        --camera-azimuth-angle=35 --camera-elevation-angle=25 "${@:3}"
}
draw "$out/menger.stl" docs/mesh-menger.png --color=0.85,0.85,0.8
draw "$out/mandelbulb.ply" docs/mesh-mandelbulb.png --scalars=RGB --comp=-2
echo "wrote docs/mesh-menger.png and docs/mesh-mandelbulb.png"
