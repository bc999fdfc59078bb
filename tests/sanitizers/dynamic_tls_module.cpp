// The module of dynamic_tls_holder.cpp: a thread-local in a library loaded with dlopen, which
// glibc keeps in a block it allocates for each thread on first use (dynamic TLS).
#include <cstdlib>

static thread_local void* held = nullptr;

// Makes the calling thread's block (its first use) and keeps `bytes` of heap through it alone.
// Returns the thread-local's address: the block's beginning.
extern "C" void* hold_through_thread_local(std::size_t bytes) {
    held = std::malloc(bytes);
    return &held;
}
