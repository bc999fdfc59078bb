#!/usr/bin/env bash
# Builds the test suite with a sanitizer (gcc) into build-<kind>/ and runs it with ctest.
#   scripts/sanitize.sh asan   AddressSanitizer + UndefinedBehaviorSanitizer (float-cast-overflow
#                              too, which -fsanitize=undefined leaves out), the whole suite
#   scripts/sanitize.sh tsan   ThreadSanitizer, the threading tests (their job system is plain
#                              std::thread: oneTBB is not instrumented, and TSan reports its
#                              internals as races)
# Any report fails the run (halt_on_error). Expects the dependencies installed
# (scripts/install-deps.sh). Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
kind=${1:?usage: scripts/sanitize.sh asan|tsan [ctest arguments]}
shift
case "$kind" in
  asan)
    flags="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer"
    # intercept_tls_get_addr=0: the runtime's __tls_get_addr interceptor (gcc 12's, as clang
    # 14's) takes a dynamic TLS block that malloc placed 16 bytes past a page boundary for one of
    # glibc 2.19 to 2.24, which wrote a header there, reads the allocator's chunk header before
    # it as that block's address and size, and LeakSanitizer's tracer then dies scanning that
    # range at exit ("Tracer caught signal 11", "LeakSanitizer has encountered a fatal error"),
    # with no leak found. A program that loads the image module (OpenImageIO's libraries,
    # dlopen'ed: their thread-locals are such blocks) failed so, now and then, depending on where
    # its blocks landed. Without the interceptor, memory held through such a block still counts
    # as reachable and memory lost through one is still reported (the first is what
    # tests/sanitizers/dynamic_tls_holder.cpp checks; both were checked by hand).
    export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:intercept_tls_get_addr=0"
    export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
    # Leaks inside uninstrumented system libraries (fontconfig through OpenImageIO's text) are theirs.
    export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"
    # Not instrumented code: the Arm check runs a cross-built binary under qemu, the packaging
    # tests build homcull and consumers of their own, and Python cannot load an instrumented libhomcull.so
    # without preloading the sanitizer runtime (c_interface_ctypes). The main run has all of them.
    filter=(-E "simd_kernels_on_arm_give_the_reference_bits|package_|subproject_|c_interface_ctypes")
    ;;
  tsan)
    flags="-fsanitize=thread -fno-omit-frame-pointer"
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1"
    # The tests whose work runs on several threads through the library's job-system interface:
    # renders, queries, clusters, the draw order, the reference cells and the C interface
    # (test::parallel_jobs: std::threads under TSan). Tests that cast ground truth are left
    # out: the truth library runs Embree and its tiles on oneTBB, which TSan cannot see into.
    filter=(-R "RenderThreads|HiddenTriangleSkip|FrameAllocations|OccluderClusters|ClusteredRender\.(TaskList|SameBits|ManyClusters)|ReferenceCells|DrawOrder|CApi|RenderCalls|IsaChoice")
    ;;
  *) echo "sanitize.sh: unknown kind '$kind' (asan or tsan)" >&2; exit 2 ;;
esac
dir="build-$kind"
generator=()
if [ ! -f "$dir/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DHOMCULL_BUILD_TESTS=ON \
  -DHOMCULL_SANITIZE="$kind" -DCMAKE_CXX_FLAGS="$flags -g1" -DCMAKE_C_FLAGS="$flags -g1" \
  -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" -DCMAKE_MODULE_LINKER_FLAGS="$flags"
cmake --build "$dir" --parallel "$(nproc)"
cd "$dir"
ctest --output-on-failure --parallel "$(nproc)" --timeout 1800 "${filter[@]}" "$@"
