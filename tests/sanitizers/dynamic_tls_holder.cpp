// The leak check at exit with a dynamic TLS block 16 bytes past a page boundary, for
// scripts/sanitize.sh's intercept_tls_get_addr=0 (the comment there says why): run under the
// AddressSanitizer suite's options, it must end with 0 and no report. Without that option, gcc
// 12's runtime takes such a block for one of glibc 2.19 to 2.24 (which wrote a header before
// it), reads the allocator's chunk header there as the block's address and size, and
// LeakSanitizer's tracer dies at exit.
//
// A thread allocates blocks of the size class glibc's allocation of the module's block falls
// in (8 bytes) until the allocator's next one is at page + 16 (it hands a thread's blocks of a
// class out in ascending order), then makes its block, keeps heap memory through it alone and
// stays alive while the program exits, so that LeakSanitizer scans it.
//     dynamic_tls_holder MODULE      exit 0: checked; 77: the block landed elsewhere (skipped)
#include <dlfcn.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace {

constexpr std::uintptr_t kPage = 4096;
void* padding[4096];  // the placement's blocks: reachable from here, not leaks

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: dynamic_tls_holder MODULE\n");
        return 2;
    }
    void* module = dlopen(argv[1], RTLD_NOW);
    if (!module) {
        std::fprintf(stderr, "dynamic_tls_holder: %s\n", dlerror());
        return 2;
    }
    using Hold = void* (*)(std::size_t);
    const auto hold = reinterpret_cast<Hold>(dlsym(module, "hold_through_thread_local"));
    if (!hold) {
        std::fprintf(stderr, "dynamic_tls_holder: %s\n", dlerror());
        return 2;
    }
    std::atomic<std::uintptr_t> block{0};
    std::thread holder([&] {
        for (void*& p : padding) {
            p = std::malloc(8);
            if (reinterpret_cast<std::uintptr_t>(p) % kPage == kPage - 16) break;
        }
        block = reinterpret_cast<std::uintptr_t>(hold(1000));
        for (;;) pause();  // alive at exit: LeakSanitizer scans its TLS
    });
    while (block == 0) std::this_thread::yield();
    holder.detach();
    const std::uintptr_t offset = block % kPage;
    std::printf("dynamic_tls_holder: the thread's block is at page + %ju\n", static_cast<std::uintmax_t>(offset));
    std::fflush(stdout);
    if (offset != 16) return 77;  // placed elsewhere: nothing checked
    return 0;                     // LeakSanitizer's check follows, at exit
}
