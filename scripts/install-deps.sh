#!/usr/bin/env bash
# Installs every Debian 12 package homcull needs to build, test and benchmark.
# Idempotent: packages already present are left alone. Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libglm-dev                      # math vocabulary (the core library's public headers use it)
  libembree-dev libtbb-dev        # ground truth ray casts; TBB drives the tools' parallel-for
  libopenimageio-dev openimageio-tools  # image dumps (id images, buffer and pyramid EXR/PNG dumps)
  fonts-dejavu-core               # the legend text of the PNG dumps (OIIO render_text; its default font is not packaged)
  chromium                        # the test that walk's HTML report renders with every image (headless)
  libassimp-dev zlib1g-dev        # scene import; assimp's CMake target links libz.so but does not depend on it
  libhwy-dev                      # SIMD with runtime dispatch (rasterizer)
  libmeshoptimizer-dev            # occluder simplification
  libcli11-dev nlohmann-json3-dev libfmt-dev
  jq                              # scripts/walk-results.sh reads the walk JSON
  valgrind                        # scripts/count-instructions.sh (callgrind: work counted without the host's noise)
  libtinygltf-dev                 # glTF/GLB import and export (keeps node order and extras)
  assimp-testmodels               # test data: the IFC source of fzk_haus.glb, for the IFC import test
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev        # the fuzzers (libFuzzer, scripts/fuzz.sh)
  libgmp-dev                      # the conservativeness tests' exact rational oracle (gmpxx)
  python3                         # the C interface's ctypes test (tests/python)
  python3-matplotlib              # scripts/frontier_plot.py (the efficiency / frame-time plot)
  g++-aarch64-linux-gnu           # the test that the SIMD kernels compile for Arm NEON/SVE (scripts/check-neon.sh)
)
# ... and give the scalar path's bits there, run under qemu (scripts/check-neon.sh --run): arm64
# builds of the libraries the core links, from Debian's multiarch. Installed in a second,
# best-effort step (below): the test skips without them.
arm_packages=(qemu-user-static libhwy1:arm64 libmeshoptimizer2d:arm64)

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

# No "| grep -q" under pipefail: grep leaving at its first match can kill the writer (SIGPIPE).
installed() { [ "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" = "install ok installed" ]; }
export DEBIAN_FRONTEND=noninteractive

missing=()
for p in "${packages[@]}"; do installed "$p" || missing+=("$p"); done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed" >&2
else
  echo "install-deps: installing ${missing[*]}" >&2
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The arm64 step: a source without arm64 indices (or no network for them) must not undo the
# build's packages above, nor leave dpkg with an architecture apt cannot update.
arm_missing=()
for p in "${arm_packages[@]}"; do installed "$p" || arm_missing+=("$p"); done
if [ ${#arm_missing[@]} -ne 0 ]; then
  echo "install-deps: installing ${arm_missing[*]} (optional: the Arm run-time check)" >&2
  added_arm64=0
  if [[ " $(dpkg --print-foreign-architectures | paste -sd' ') " != *" arm64 "* ]]; then
    "${sudo_cmd[@]}" dpkg --add-architecture arm64
    added_arm64=1
  fi
  if ! { "${sudo_cmd[@]}" apt-get update -q && "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${arm_missing[@]}"; }; then
    echo "install-deps: WARNING: could not install ${arm_missing[*]}; the Arm run-time check will be skipped" >&2
    if [ "$added_arm64" -eq 1 ]; then
      "${sudo_cmd[@]}" dpkg --remove-architecture arm64 || true
      "${sudo_cmd[@]}" apt-get update -q || true
    fi
  fi
fi
