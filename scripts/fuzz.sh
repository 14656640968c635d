#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`: clang, -fsanitize=fuzzer,address,undefined)
# and runs each for SECONDS (default 20), one at a time, on its seed corpus
# tests/fuzz/corpus/<target>/ (read only: new inputs go to build/fuzz/corpus/<target>/).
# A crash leaves its input in build/fuzz/artifacts/ and fails the script (docs/fuzzing.md).
#   scripts/fuzz.sh [SECONDS] [TARGET...]      targets: grammar skeleton scene gltf image
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${1:-20}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(grammar skeleton scene gltf image)

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
mkdir -p build/fuzz/artifacts
for t in "${targets[@]}"; do
  echo "== fuzz $t: ${seconds} s"
  mkdir -p "build/fuzz/corpus/$t"
  # rss/malloc limits: an input that makes a reader take more than 2 GiB is a finding;
  # -timeout: one input running past 10 s is a hang.
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0" \
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  "build/fuzz/tests/fuzz/sylva_fuzz_$t" "build/fuzz/corpus/$t" "tests/fuzz/corpus/$t" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
    -artifact_prefix="build/fuzz/artifacts/$t-" -print_final_stats=1 2>&1 | tail -n 80
done
