#!/usr/bin/env bash
# Checks that homcull::core, the SIMD rasterizer in particular, compiles for ARM NEON (aarch64).
#
# Why: the project is built and tested on x86-64 only, but the Highway kernels
# (lib/raster/rasterize_simd.cpp, compiled once per target with hwy/foreach_target.h) must also
# compile for NEON, and on aarch64 Highway 1.0.3 also builds its SVE targets (SVE, SVE2,
# SVE_256, SVE2_128) from the same code. Code that is fine on x86 can fail there (SVE vectors
# are sizeless: no arrays of vectors, no sizeof, no vectors as struct members).
#
# What: compiles (-c) every source of homcull_core with the aarch64 cross compiler and the core
# target's flags; then checks that every source using hwy/foreach_target.h defines functions in
# namespace N_NEON (and lists the other targets built), and that
# homcull::detail::N_NEON::RasterizeRows exists and uses NEON vector registers. Kernels that
# are HWY_INLINE (e.g. UpdateSubtileRow) have no symbol of their own; they are compiled, and
# checked, inside their callers. Without --run nothing is linked or run (no aarch64 machine or
# emulator is needed).
#
# Why not CMake with a toolchain file: lib/CMakeLists.txt defines all the libraries in one
# file and find_package()s TBB, Embree, assimp, OpenImageIO and nlohmann_json unconditionally,
# none of which is installed for arm64, so a cross configure fails before homcull_core is
# reached. The script therefore calls the compiler itself. The source list is read from the
# add_library(homcull_core ...) call in lib/CMakeLists.txt, so it cannot go stale; the flags
# below mirror that target (C++17, -ffp-contract=off, include dirs lib/include and lib), the
# top-level Release flags (-O3 -DNDEBUG) and cmake/HomcullWarnings.cmake.
#
# With --run it then also runs them: tests/isa_bits_check.cpp (every instruction set against
# the scalar reference path: buffer bits, statistics, rectangle, box, triangle and maps answers)
# is linked with those objects and the arm64 builds of Highway's and meshoptimizer's libraries
# (Debian multiarch), and run under qemu-aarch64 with -cpu max, which has NEON, SVE and SVE2,
# at SVE vector lengths of 128, 256 and 512 bits (4-6 minutes in all), with the arm64 loader and
# C library of the same multiarch packages.
#
# Usage: scripts/check-neon.sh [--run] [extra compiler flags, e.g. -Werror]
#   Installs g++-aarch64-linux-gnu with apt-get when it is missing and the script runs as root.
#   --run needs qemu-user-static, libhwy1:arm64 and libmeshoptimizer2d:arm64, which
#   scripts/install-deps.sh installs; without them it exits 2 (the test suite then counts the
#   check as skipped). AARCH64_CXX overrides the compiler (default aarch64-linux-gnu-g++).
# Exit status: 0 when everything compiled, the NEON symbols are there and (--run) every
# instruction set gave the scalar reference's bits; 1 otherwise; 2 when a tool or library is
# missing.
set -euo pipefail
cd "$(dirname "$0")/.."

run=0
if [ "${1:-}" = "--run" ]; then
  run=1
  shift
fi

cxx=${AARCH64_CXX:-aarch64-linux-gnu-g++}
nm=aarch64-linux-gnu-nm
objdump=aarch64-linux-gnu-objdump

# --- The cross compiler -------------------------------------------------------------------
if ! command -v "$cxx" >/dev/null 2>&1 || ! command -v "$nm" >/dev/null 2>&1; then
  if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "check-neon: installing the aarch64 cross compiler (g++-aarch64-linux-gnu)..."
    if ! DEBIAN_FRONTEND=noninteractive apt-get install -y -qq g++-aarch64-linux-gnu >/dev/null; then
      apt-get update -qq
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq g++-aarch64-linux-gnu >/dev/null
    fi
  else
    echo "check-neon: $cxx (or $nm) not found. Install the cross compiler first, e.g." >&2
    echo "  sudo apt-get install g++-aarch64-linux-gnu" >&2
    exit 2
  fi
fi
for tool in "$cxx" "$nm" "$objdump"; do
  command -v "$tool" >/dev/null 2>&1 || { echo "check-neon: $tool not found" >&2; exit 2; }
done

# --- Headers ------------------------------------------------------------------------------
# Highway and GLM are header-only here (nothing is linked) and their headers do not depend on
# the architecture, so the host's copies are used. Only those two folders are exposed to the
# cross compiler: adding -I/usr/include would pull in the host's x86-64 glibc headers.
for h in /usr/include/hwy/highway.h /usr/include/glm/glm.hpp; do
  [ -f "$h" ] || { echo "check-neon: $h missing (run scripts/install-deps.sh)" >&2; exit 2; }
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/homcull-check-neon.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/include" "$tmp/obj"
ln -s /usr/include/hwy "$tmp/include/hwy"
ln -s /usr/include/glm "$tmp/include/glm"

# --- Sources of homcull_core, from lib/CMakeLists.txt ----------------------------------------
# The .cpp files of the layers: every homcull_layer(...) call, up to "set(homcull_layers".
mapfile -t sources < <(sed -n '/^homcull_layer(common/,/^set(homcull_layers/p' lib/CMakeLists.txt |
  sed -e 's/#.*//' | tr -s ' \t()' '\n' | grep '\.cpp$' || true)
if [ "${#sources[@]}" -eq 0 ]; then
  echo "check-neon: found no layer sources (homcull_layer(...)) in lib/CMakeLists.txt" >&2
  exit 1
fi
simd_source=raster/rasterize_simd.cpp
# Matched in bash, not with "printf ... | grep -q": under pipefail, grep -q leaving at the first
# match kills printf (which writes line by line) with SIGPIPE now and then, and the check fails.
listed=0
for src in "${sources[@]}"; do [ "$src" = "$simd_source" ] && listed=1; done
[ "$listed" -eq 1 ] ||
  { echo "check-neon: $simd_source is no longer a source of homcull_core; update this script" >&2; exit 1; }

# --- Compile ------------------------------------------------------------------------------
flags=(-std=c++17 -O3 -DNDEBUG -fPIC -ffp-contract=off
       -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Wunused
       -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough
       -isystem "$tmp/include" -Ilib/include -Ilib "$@")
hwy_version=$(sed -n 's/^#define HWY_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' /usr/include/hwy/highway.h | paste -sd.)
echo "check-neon: $("$cxx" --version | sed -n 1p), Highway headers $hwy_version"
failed=()
for src in "${sources[@]}"; do
  obj="$tmp/obj/${src//\//_}.o"
  echo "  compiling lib/$src"
  if ! "$cxx" "${flags[@]}" -c "lib/$src" -o "$obj"; then failed+=("lib/$src"); fi
done
if [ "${#failed[@]}" -ne 0 ]; then
  echo "check-neon: FAILED: ${#failed[@]} of ${#sources[@]} sources do not compile for aarch64:" >&2
  printf '  %s\n' "${failed[@]}" >&2
  exit 1
fi

# --- Check the Highway targets ----------------------------------------------------------------
# Every source that includes hwy/foreach_target.h must define functions in namespace N_NEON;
# the other targets found (N_SVE... on Highway 1.0.3) are listed, not required.
status=0
for src in "${sources[@]}"; do
  grep -q 'hwy/foreach_target\.h' "lib/$src" || continue
  obj="$tmp/obj/${src//\//_}.o"
  # "homcull::detail::N_NEON::RasterizeRows(...)" -> "N_NEON RasterizeRows"
  kernels=$("$nm" -C --defined-only "$obj" |
    sed -n 's/^[0-9a-f]* [TtWw] homcull::\(.*::\)\{0,1\}\(N_[A-Z0-9_]*\)::\([A-Za-z_][A-Za-z0-9_]*\)(.*/\2 \3/p' | sort -u)
  targets=$(printf '%s\n' "$kernels" | awk 'NF {print $1}' | sort -u | paste -sd' ')
  neon_functions=$(printf '%s\n' "$kernels" | awk '$1 == "N_NEON" {print $2}' | paste -sd' ')
  echo "check-neon: lib/$src: targets ${targets:-none}; N_NEON functions: ${neon_functions:-none}"
  if [ -z "$neon_functions" ]; then
    echo "check-neon: FAILED: lib/$src defines no function in namespace N_NEON" >&2
    status=1
  fi
done
[ "$status" -eq 0 ] || exit 1

simd_obj="$tmp/obj/${simd_source//\//_}.o"
neon_symbol=$("$nm" --defined-only "$simd_obj" | awk '!found && $3 ~ /6N_NEON13RasterizeRows/ {print $3; found = 1}')
if [ -z "$neon_symbol" ]; then
  echo "check-neon: FAILED: no homcull::detail::N_NEON::RasterizeRows in lib/$simd_source's object" >&2
  exit 1
fi
# The NEON kernel must really be vector code: 4 x 32-bit lanes in v registers (e.g. v3.4s).
neon_ops=$("$objdump" -d --no-show-raw-insn --disassemble="$neon_symbol" "$simd_obj" |
  grep -cE '\bv[0-9]+\.4s\b' || true)
if [ "$neon_ops" -eq 0 ]; then
  echo "check-neon: FAILED: N_NEON::RasterizeRows has no NEON (vN.4s) instructions" >&2
  exit 1
fi
echo "check-neon: OK: ${#sources[@]} sources of homcull_core compile for aarch64;" \
  "N_NEON::RasterizeRows has $neon_ops NEON vector instructions"

[ "$run" -eq 1 ] || exit 0

# --- Run every instruction set against the scalar reference, under qemu ------------------------
arm_libs=(/usr/lib/aarch64-linux-gnu/libhwy.so.1 /usr/lib/aarch64-linux-gnu/libmeshoptimizer.so.2d)
missing=0
command -v qemu-aarch64-static >/dev/null 2>&1 || missing=1
for lib in "${arm_libs[@]}"; do [ -e "$lib" ] || missing=1; done
if [ "$missing" -eq 1 ]; then
  echo "check-neon: --run needs qemu-user-static, libhwy1:arm64 and libmeshoptimizer2d:arm64" \
    "(scripts/install-deps.sh installs them); skipped" >&2
  exit 2
fi
echo "check-neon: linking tests/isa_bits_check.cpp for aarch64"
"$cxx" "${flags[@]}" tests/isa_bits_check.cpp "$tmp"/obj/*.o "${arm_libs[@]}" -o "$tmp/isa_bits_check"
# NEON (128-bit) once, with the first pass; SVE and SVE2 at each vector length, and Highway's
# builds for exactly 256-bit SVE and 128-bit SVE2 vectors at those lengths.
for bytes in 64 32 16; do
  case "$bytes" in
    64) isas=(sve2 sve neon) ;;
    32) isas=(sve_256 sve2 sve) ;;
    16) isas=(sve2_128 sve2 sve) ;;
  esac
  echo "check-neon: running it under qemu-aarch64 -cpu max with SVE vectors of $((bytes * 8)) bits: ${isas[*]}"
  if ! qemu-aarch64-static -cpu "max,sve-default-vector-length=$bytes" "$tmp/isa_bits_check" "${isas[@]}"; then
    status=1
  fi
done
if [ "$status" -ne 0 ]; then
  echo "check-neon: FAILED: an instruction set differs from the scalar reference on aarch64" >&2
  exit 1
fi
echo "check-neon: OK: NEON, SVE and SVE2 give the scalar reference's bits and answers (qemu-aarch64)"
