#!/usr/bin/env bash
# Installs the dependencies, builds homcull (Release, warnings as errors) and runs the whole
# test suite with ctest. Tests that need ../shared/scenes skip, saying so, when it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DHOMCULL_WARNINGS_AS_ERRORS=ON -DHOMCULL_BUILD_TESTS=ON
cd build
ctest --output-on-failure --parallel "$(nproc)" --timeout 900
