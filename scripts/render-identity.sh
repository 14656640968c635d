#!/usr/bin/env bash
# Renders every bundled preset and scene on both backends (and the scenes' mesh baseline;
# fog scenes on the CPU, which alone renders their default fog mode, auto, for now), grows
# every preset's skeleton and exports every preset and scene as glTF (with and without
# the mesh) into a folder, so that two builds can be compared byte for byte: a refactor
# that must not change behaviour shows `identical` for every file.
#
#   scripts/render-identity.sh SYLVA_BINARY OUT_DIR          # render
#   scripts/render-identity.sh --compare DIR_A DIR_B         # compare two renders
#
# Images are small (160×120, 2 samples per pixel) with every AOV in EXR next to a PNG, so
# the whole set takes a few minutes on llvmpipe. Exit status 1 when a compare differs.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--compare" ]; then
  a=$2 b=$3 status=0 n=0
  for f in "$a"/*; do
    name=$(basename "$f")
    n=$((n + 1))
    if [ ! -f "$b/$name" ]; then echo "missing in $b: $name"; status=1
    elif ! cmp -s "$f" "$b/$name"; then echo "differs: $name"; status=1; fi
  done
  for f in "$b"/*; do [ -f "$a/$(basename "$f")" ] || { echo "missing in $a: $(basename "$f")"; status=1; }; done
  [ $status -eq 0 ] && echo "identical: $n files"
  exit $status
fi

sylva=$1 out=$2
mkdir -p "$out"
size=(--width 160 --height 120 --spp 2)
for input in presets/*.lsys presets/scenes/*.scene.json; do
  name=$(basename "$input"); name=${name%%.*}
  case "$input" in *.scene.json) name="scene_$name";; esac
  backends="cpu gl"
  fog=() aovs=depth,normal,uv,id mesh_aovs=depth
  if grep -q '"fog"' "$input"; then
    # Fog: the CPU renders it (with the fog AOV, few photons and steps to stay quick).
    backends=cpu
    fog=(--photons 20000 --fog-steps 8) aovs=$aovs,fog mesh_aovs=depth,fog
  fi
  for backend in $backends; do
    "$sylva" render "$input" -o "$out/${name}_$backend.png" --backend "$backend" "${size[@]}" \
      --aov "$aovs" "${fog[@]}" >/dev/null 2>"$out/${name}_$backend.log" || {
        echo "render failed: $input ($backend)"; cat "$out/${name}_$backend.log"; exit 1; }
    rm -f "$out/${name}_$backend.log"
  done
  case "$input" in *.scene.json)
    for backend in $backends; do
      "$sylva" render "$input" -o "$out/${name}_mesh_$backend.png" --backend "$backend" "${size[@]}" \
        --geometry mesh --mesh-level 1 --aov "$mesh_aovs" "${fog[@]}" >/dev/null 2>&1 || { echo "mesh render failed: $input ($backend)"; exit 1; }
    done;;
  esac
done
# Skeletons and glTF exports: the same bytes from the same inputs.
for input in presets/*.lsys; do
  name=$(basename "$input" .lsys)
  "$sylva" grow "$input" -o "$out/${name}.skel.json" >/dev/null || { echo "grow failed: $input"; exit 1; }
  "$sylva" export "$input" -o "$out/${name}.gltf" >/dev/null || { echo "export failed: $input"; exit 1; }
  "$sylva" export "$input" -o "$out/${name}_mesh.glb" --mesh >/dev/null || { echo "mesh export failed: $input"; exit 1; }
done
for input in presets/scenes/*.scene.json; do
  name=scene_$(basename "$input" .scene.json)
  "$sylva" export "$input" -o "$out/${name}_mesh.glb" --mesh >/dev/null || { echo "export failed: $input"; exit 1; }
done
echo "rendered and exported $(ls "$out" | wc -l) files into $out"
