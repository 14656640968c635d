#!/usr/bin/env bash
# Installs everything sylva needs on Debian 12, from Debian's packages only.
# Idempotent: running it again installs nothing new. Run as root (or with sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libgtest-dev libgmock-dev libbenchmark-dev
  libembree-dev  # Embree 3: the peer that `sylva bench raycast` measures against
  libnanoflann-dev  # kd-tree of the shadow-cone clustering (core/light/shadow_cones.cpp)
  # The design card's libraries; later stages link them (render, GUI, export).
  libglm-dev libglfw3-dev libimgui-dev libopenimageio-dev libtinygltf-dev
  libmeshoptimizer-dev  # `sylva export --compress meshopt` (EXT_meshopt_compression)
  # The Python module (built for /usr/bin/python3) and its tests.
  python3 python3-dev pybind11-dev python3-numpy python3-pytest
  python3-distributed  # sylva_dask: batches of seeds on a dask.distributed cluster
  fonts-dejavu-core  # the text of the benchmarks' plots (core/plot.h)
  # The GL backend: OpenGL 4.5 + EGL through libglvnd, Mesa's llvmpipe for a machine
  # without a GPU (surfaceless EGL, no X), glslangValidator for the shader tests.
  libgl-dev libegl-dev libgl1-mesa-dri libegl-mesa0 glslang-tools
  # The studio's window tests: a virtual X server (xvfb-run) and simulated input.
  xvfb xauth xdotool
  ffmpeg  # `sylva render --frames ... --video` encodes with it; its ffprobe checks the tests' videos
  blender  # tests/app/blender_check_test.cpp: Blender's glTF importer reads what `sylva export` writes
  # The fuzz targets (tests/fuzz, scripts/fuzz.sh): clang with libFuzzer and its sanitizers.
  clang
)
# Node.js runs the Khronos glTF validator; any npm already on the machine will do.
command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} Debian packages already installed"
else
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator (npm), pinned, installed inside the repo (git-ignored).
validator_version=2.0.0-dev.3.10
tools="$(cd "$(dirname "$0")/.." && pwd)/.tools/node"
if [ ! -f "$tools/node_modules/gltf-validator/package.json" ] || \
   ! grep -q "\"version\": \"$validator_version\"" "$tools/node_modules/gltf-validator/package.json"; then
  echo "setup: installing gltf-validator@$validator_version into .tools/node"
  mkdir -p "$tools"
  npm install --silent --no-audit --no-fund --prefix "$tools" "gltf-validator@$validator_version"
fi
# three.js (npm), pinned, for tests/app/three_check_test.cpp: its GLTFLoader and
# AnimationMixer play an exported wind clip (scripts/three_check.mjs).
three_version=0.187.0
if [ ! -f "$tools/node_modules/three/package.json" ] || \
   ! grep -q "\"version\": \"$three_version\"" "$tools/node_modules/three/package.json"; then
  echo "setup: installing three@$three_version into .tools/node"
  mkdir -p "$tools"
  npm install --silent --no-audit --no-fund --prefix "$tools" "three@$three_version"
fi
