#!/usr/bin/env bash
# Renders every bundled preset (presets/*.lsys, each in its default scene: the plant at the
# origin, framed by the default camera) and the single-plant scenes that dress the paper's
# plants (bark relief, needle and frond colours), then tiles them into the contact sheet
# docs/images/presets.png, each picture labelled with its preset's name and segment count
# (and its polygon leaves, and the paper's count for the paper's plants).
#
#   scripts/render-presets.sh [SYLVA_BINARY] [OUT_DIR]
#       SYLVA_BINARY  default build/release/app/sylva
#       OUT_DIR       where the single pictures go (PNG), default out/presets
#   environment: BACKEND (default cpu), WIDTH x HEIGHT (320 x 240), SPP (8, as `sylva render`)
#
# The CPU ray caster is the default: on the shared 2-core machine without a GPU it is the
# faster backend (the pine at 320 x 240: 3.4 s on the CPU, 17 s on llvmpipe, load 11);
# BACKEND=gl uses OpenGL where there is a GPU. The whole sheet took 25 s on the CPU here
# (29 pictures, load 1.7; 42 s for 24 pictures at load 11 to 13). The sheet is written by scripts/contact_sheet.py (numpy only).
set -euo pipefail
cd "$(dirname "$0")/.."

sylva=${1:-build/release/app/sylva}
out=${2:-out/presets}
backend=${BACKEND:-cpu} width=${WIDTH:-320} height=${HEIGHT:-240} spp=${SPP:-8}
mkdir -p "$out" docs/images

# Table 1 of Bhagvat et al. 2009 (Bhagvat, Jeschke, Cline, Wonka 2009): the segment counts of its plants.
paper_count() {
  case $1 in
    pine | pine_dense) echo 16997 ;; coconut_palm) echo 3713 ;; elm | elm_in_leaf) echo 1833 ;;
    aloe_vera) echo 229 ;; saguaro) echo 30 ;; *) echo "" ;;
  esac
}

# 12345 -> 12,345
commas() { printf "%s" "$1" | sed ':a;s/\B[0-9]\{3\}\>/,&/;ta'; }

sheet=()
start=$(date +%s)
for grammar in presets/*.lsys; do
  name=$(basename "$grammar" .lsys)
  summary=$("$sylva" grow "$grammar" -o "$out/$name.skel.json")
  segments=$(printf "%s" "$summary" | sed -n 's/.* \([0-9]*\) segments.*/\1/p')
  leaves=$(/usr/bin/python3 -c "import json,sys; print(len(json.load(open(sys.argv[1])).get('leaves', [])))" \
    "$out/$name.skel.json")
  # Three lines: the name, the segments, then the paper's count and the leaves.
  paper=$(paper_count "$name") extra=""
  [ -n "$paper" ] && extra="paper $(commas "$paper")"
  [ "$leaves" -gt 0 ] && extra="${extra:+$extra, }$(commas "$leaves") leaves"
  label="$(commas "$segments") segments${extra:+|$extra}"
  t0=$(date +%s.%N)
  "$sylva" render "$out/$name.skel.json" -o "$out/$name.png" --width "$width" --height "$height" --spp "$spp" \
    --backend "$backend" 2>/dev/null
  printf "%-24s %s  (%.1f s)\n" "$name" "${label/|/, }" "$(echo "$(date +%s.%N) - $t0" | bc)"
  sheet+=("$out/$name.png" "$name|$label")
done
# The paper's plants, the fir and the Scots pine dressed by their scenes; rendered at the sheet's size.
for scene in pine_dense coconut_palm saguaro aloe_vera fir scots_pine; do
  t0=$(date +%s.%N)
  "$sylva" render "presets/scenes/$scene.scene.json" -o "$out/scene_$scene.png" --width "$width" \
    --height "$height" --spp "$spp" --backend "$backend" 2>/dev/null
  printf "%-24s %s  (%.1f s)\n" "scenes/$scene" "scene" "$(echo "$(date +%s.%N) - $t0" | bc)"
  case $scene in
    aloe_vera) note="flecked skin on the leaves|(materials table)" ;;
    scots_pine) note="orange upper bark|(materials table)" ;;
    *) note="bark relief on wood|(material 0) only" ;;
  esac
  sheet+=("$out/scene_$scene.png" "$scene.scene.json|$note")
done
/usr/bin/python3 scripts/contact_sheet.py docs/images/presets.png 5 "${sheet[@]}"
echo "docs/images/presets.png: $((${#sheet[@]} / 2)) pictures of ${width}x${height}, $spp spp, $backend backend," \
  "$(($(date +%s) - start)) s (load $(cut -d' ' -f1-3 /proc/loadavg))"
