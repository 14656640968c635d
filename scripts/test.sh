#!/usr/bin/env bash
# The README's second command: build and run the whole test suite twice — an optimised
# build, and an AddressSanitizer + UndefinedBehaviorSanitizer build — with CTest.
# Installs missing dependencies first (idempotent).
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" -eq 0 ]; then bash scripts/setup.sh; else sudo bash scripts/setup.sh; fi
for preset in release asan; do
  echo "== $preset: configure, build, test"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  ctest --preset "$preset"
done
