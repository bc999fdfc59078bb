#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer into build-fuzz/, then runs each for SECONDS (default 60) from its
# seed corpus (tests/fuzz/corpus/<target>). New inputs go to build-fuzz/corpus/<target>, crashes
# to build-fuzz/crashes/<target>; the repository's corpus is only read. Fails when a target
# crashes, leaks, hangs (20 s on one input) or reports undefined behaviour.
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]     targets: fuzz_scene_import fuzz_buffer fuzz_conservative fuzz_c_interface
# A long run: bash scripts/fuzz.sh 3600 (an hour each). Expects scripts/install-deps.sh's packages.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_scene_import fuzz_buffer fuzz_conservative fuzz_c_interface)
flags="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fsanitize=fuzzer-no-link -fno-omit-frame-pointer -g1"
generator=()
if [ ! -f build-fuzz/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DHOMCULL_BUILD_FUZZERS=ON \
  -DHOMCULL_BUILD_TOOLS=OFF -DHOMCULL_BUILD_TESTS=OFF -DHOMCULL_INSTALL=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
cmake --build build-fuzz --parallel "$(nproc)" --target "${targets[@]}"
# intercept_tls_get_addr=0: scripts/sanitize.sh says why (a LeakSanitizer crash at exit).
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
status=0
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/crashes/$t"
  echo "fuzz: $t for $seconds s" >&2
  if ! "build-fuzz/tests/fuzz/$t" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 -print_final_stats=1 \
       -artifact_prefix="build-fuzz/crashes/$t/" "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" 2>"build-fuzz/$t.log"; then
    echo "fuzz: $t FAILED (build-fuzz/$t.log, inputs in build-fuzz/crashes/$t):" >&2
    # The report's head (the error and its stacks), then the end (the input written).
    sed -n '/ERROR: \|runtime error:\|deadly signal/,$p' "build-fuzz/$t.log" | head -60 >&2 || true
    tail -6 "build-fuzz/$t.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "build-fuzz/$t.log" | sed "s/^/fuzz: $t: /" >&2 || true
    echo "fuzz: $t clean" >&2
  fi
done
exit $status
