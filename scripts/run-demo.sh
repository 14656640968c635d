#!/usr/bin/env bash
# The README's first command: install dependencies (Debian 12), build sylva (release),
# and grow the bundled saguaro and elm presets, printing their summaries.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" -eq 0 ]; then bash scripts/setup.sh; else sudo bash scripts/setup.sh; fi
cmake --preset release >/dev/null
cmake --build --preset release --target sylva
mkdir -p out
for plant in saguaro elm; do
  build/release/app/sylva grow "presets/$plant.lsys" -o "out/$plant.skel.json"
done
echo "skeletons written to out/ (see docs/ for the file format and the other presets)"
