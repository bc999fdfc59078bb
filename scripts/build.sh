#!/usr/bin/env bash
# Configures and builds homcull (Release, -O3) into build/. Extra arguments go to cmake's
# configure step, e.g. scripts/build.sh -DHOMCULL_WARNINGS_AS_ERRORS=ON
set -euo pipefail
cd "$(dirname "$0")/.."
generator=()
if [ ! -f build/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build --parallel "$(nproc)"
