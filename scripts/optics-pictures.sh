#!/usr/bin/env bash
# Renders the pictures in `docs/` of the camera's optics and of cuts with
# `fractal-sdf render`:
#
#   docs/depth-of-field.png       the depth_of_field scene, 32 progressive passes
#   docs/progressive-1.png        the same at 320x200 after 1 pass,
#   docs/progressive-64.png       and after 64
#   docs/stereo-anaglyph.png      the Mandelbulb as a red-cyan anaglyph
#   docs/stereo-side-by-side.png  the Menger sponge as a side-by-side pair
#   docs/cross-section-N.png      the cross_section scene with its cut at
#                                 -0.35, 0 and 0.3
#   docs/materials.png            the materials scene, 4 progressive passes
#   docs/materials-bounces-N.png  its glass and mirror after 0, 1 and 4
#                                 bounces
#   docs/mandelbox.png            the mandelbox scene (an inside shape, brute
#                                 force), 4 progressive passes
#   docs/mandelbulb-escape-N.png  the mandelbulb_escape scene at 320x240
#                                 after 1 and 16 passes
#
#   scripts/optics-pictures.sh
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --features cli --bin fractal-sdf
bin=target/release/fractal-sdf
mkdir -p docs
render() { "$bin" render --preset production "$@"; }

render depth_of_field --size 640x400 --passes 32 -o docs/depth-of-field.png
render depth_of_field --size 320x200 -o docs/progressive-1.png
render depth_of_field --size 320x200 --passes 64 -o docs/progressive-64.png
render mandelbulb --size 480x360 --stereo anaglyph -o docs/stereo-anaglyph.png
render menger --size 320x240 --stereo side-by-side -o docs/stereo-side-by-side.png
n=0
for cut in -0.35 0 0.3; do
    n=$((n + 1))
    render cross_section --size 320x240 --set "cut=$cut" -o "docs/cross-section-$n.png"
done
render materials --size 640x400 --passes 4 -o docs/materials.png
for n in 0 1 4; do
    render materials --size 320x200 --bounces "$n" -o "docs/materials-bounces-$n.png"
done
render mandelbox --size 640x400 --passes 4 -o docs/mandelbox.png
for n in 1 16; do
    render mandelbulb_escape --size 320x240 --passes "$n" -o "docs/mandelbulb-escape-$n.png"
done
