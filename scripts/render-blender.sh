#!/usr/bin/env bash
# The bundled plants as Blender sees them: each is exported with `sylva export --mesh`
# (frusta and leaves as triangles, the scene's materials and bark texture), imported into
# Blender by scripts/blender_check.py (which checks every triangle, material and the
# skeleton in extras, and fails on a difference), rendered there with Cycles, and the
# pictures are tiled into docs/images/blender_presets.png.
#
#   scripts/render-blender.sh [SYLVA_BINARY] [OUT_DIR]
#       SYLVA_BINARY  default build/release/app/sylva
#       OUT_DIR       where the glTF files and single pictures go, default out/blender
#   environment: WIDTH x HEIGHT (320 x 240), SAMPLES (Cycles samples per pixel, 16)
#
# Needs Debian's blender (3.4; scripts/setup.sh installs it). About 1 to 8 s per plant here.
set -euo pipefail
cd "$(dirname "$0")/.."

sylva=${1:-build/release/app/sylva}
out=${2:-out/blender}
width=${WIDTH:-320} height=${HEIGHT:-240} samples=${SAMPLES:-16}
command -v blender >/dev/null || { echo "render-blender.sh: blender is not installed (scripts/setup.sh)" >&2; exit 1; }
mkdir -p "$out" docs/images

sheet=()
# INPUT|LABEL: the paper's plants in their scenes, and the leafy grammars.
for entry in "presets/scenes/pine_dense.scene.json|pine_dense scene|needles, bark texture" \
             "presets/scenes/coconut_palm.scene.json|coconut_palm scene|fronds, bark texture" \
             "presets/elm_in_leaf.lsys|elm_in_leaf|polygon leaves" \
             "presets/abop_2_6_honda_leaves.lsys|abop_2_6_honda_leaves|polygon leaves" \
             "presets/aloe_vera.lsys|aloe_vera|" \
             "presets/scenes/saguaro.scene.json|saguaro scene|"; do
  IFS='|' read -r input name note <<<"$entry"
  base=$(basename "$input"); base=${base%%.*}
  "$sylva" export "$input" --mesh -o "$out/$base.glb" >/dev/null
  t0=$(date +%s.%N)
  report=$(blender -b --factory-startup --python-exit-code 1 --python scripts/blender_check.py -- \
    "$out/$base.glb" --render "$out/$base.png" --size "${width}x${height}" --samples "$samples" 2>&1 |
    grep '^BLENDER_CHECK ') || { echo "$input: blender_check.py failed" >&2; exit 1; }
  triangles=$(printf "%s" "$report" | sed -n 's/.*"triangles_blender": \([0-9]*\).*/\1/p')
  printf "%-44s %s triangles in Blender  (%.1f s)\n" "$input" "$triangles" "$(echo "$(date +%s.%N) - $t0" | bc)"
  sheet+=("$out/$base.png" "$name|$triangles triangles${note:+|$note}")
done
/usr/bin/python3 scripts/contact_sheet.py docs/images/blender_presets.png 3 "${sheet[@]}"
echo "docs/images/blender_presets.png: $((${#sheet[@]} / 2)) Blender (Cycles, $samples samples) pictures of ${width}x${height}"
