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
  libtinygltf-dev                 # glTF/GLB import and export (keeps node order and extras)
  assimp-testmodels               # test data: the IFC source of fzk_haus.glb, for the IFC import test
  libgtest-dev libgmock-dev libbenchmark-dev
  g++-aarch64-linux-gnu           # the test that the SIMD kernels compile for Arm NEON/SVE (scripts/check-neon.sh)
  qemu-user-static libhwy1:arm64 libmeshoptimizer2d:arm64  # ... and run there with the scalar path's bits (check-neon.sh --run)
)

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed" >&2
  exit 0
fi
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
# Packages of another architecture (name:arch, Debian multiarch) need it added to dpkg first.
for p in "${missing[@]}"; do
  case "$p" in
    *:*) arch=${p##*:}
         dpkg --print-foreign-architectures | grep -qx "$arch" || "${sudo_cmd[@]}" dpkg --add-architecture "$arch" ;;
  esac
done
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
