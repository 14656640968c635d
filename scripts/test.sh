#!/usr/bin/env bash
# The README's second command: build and run the whole test suite twice — an optimised
# build, and an AddressSanitizer + UndefinedBehaviorSanitizer build — with CTest — then a
# short fuzzing smoke run (20 s per target, scripts/fuzz.sh) where clang is installed.
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

if command -v clang++ >/dev/null 2>&1; then
  echo "== fuzz: 20 s per target (docs/fuzzing.md)"
  bash scripts/fuzz.sh 20
elif [ "${SYLVA_REQUIRE_TOOLS:-}" = 1 ]; then
  echo "== fuzz: clang++ is missing and SYLVA_REQUIRE_TOOLS=1 requires it (scripts/setup.sh installs it)"
  exit 1
else
  echo "== fuzz: skipped (no clang++; scripts/setup.sh installs it)"
fi
