#!/usr/bin/env bash
# The README's first command: install dependencies (Debian 12), build sylva (release),
# grow the bundled saguaro and elm presets (printing their summaries), and render the
# saguaro with the OpenGL backend (a window-less EGL context: Mesa's llvmpipe on a machine
# without a GPU, no X server) to out/saguaro.png, then its scene (bark texture, relief-mapped
# ribs) to out/saguaro_ribs.png, and a stand of pines toward a low sun in fog, with
# crepuscular rays, on the CPU (sun photons, shadow cones, the fog's in-scatter: docs/spec/fog.md)
# to out/pine_stand_fog.png.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" -eq 0 ]; then bash scripts/setup.sh; else sudo bash scripts/setup.sh; fi
cmake --preset release >/dev/null
cmake --build --preset release --target sylva
mkdir -p out
for plant in saguaro elm; do
  build/release/app/sylva grow "presets/$plant.lsys" -o "out/$plant.skel.json"
done
build/release/app/sylva render presets/saguaro.lsys -o out/saguaro.png --width 800 --height 600 --backend gl
# The same plant in its scene: bark texture and relief-mapped ribs, marched in the shaders.
build/release/app/sylva render presets/scenes/saguaro.scene.json -o out/saguaro_ribs.png --width 800 --height 600 \
  --backend gl
# Crepuscular rays: the fog's shafts between the crowns (the default fog mode, auto, is map on the
# CPU: sun photons find where the plants are, four sun-space depth maps of them, every camera
# ray walked through the maps, docs/fog-map.md; one sample per pixel, where the default 8 would
# walk the fog 8 times: docs/benchmarks.md "Samples per pixel").
build/release/app/sylva render presets/scenes/pine_stand_low_sun.scene.json -o out/pine_stand_fog.png --width 480 \
  --height 360 --backend cpu --spp 1
echo "skeletons, out/saguaro.png, out/saguaro_ribs.png and out/pine_stand_fog.png written to out/" \
  "(see docs/ for the formats and the other presets)"
