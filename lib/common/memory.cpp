#include <homcull/detail/memory.hpp>

namespace homcull::detail {
namespace {

thread_local const MemoryHooks* current_hooks = nullptr;

}  // namespace

const MemoryHooks* current_memory_hooks() noexcept { return current_hooks; }

MemoryScope::MemoryScope(const MemoryHooks* hooks) noexcept : previous_(current_hooks) { current_hooks = hooks; }
MemoryScope::~MemoryScope() { current_hooks = previous_; }

void* hooked_allocate(const MemoryHooks* hooks, std::size_t bytes, std::size_t alignment) {
    if (!hooks) {
        if (alignment > __STDCPP_DEFAULT_NEW_ALIGNMENT__) return ::operator new(bytes, std::align_val_t(alignment));
        return ::operator new(bytes);
    }
    void* memory = hooks->allocate(hooks->user, bytes == 0 ? 1 : bytes, alignment < alignof(std::max_align_t) ? alignof(std::max_align_t) : alignment);
    if (!memory) throw std::bad_alloc();
    return memory;
}

void hooked_deallocate(const MemoryHooks* hooks, void* memory, std::size_t bytes, std::size_t alignment) noexcept {
    if (!memory) return;
    if (!hooks) {
        // The unsized forms: clang leaves sized deallocation off by default.
        if (alignment > __STDCPP_DEFAULT_NEW_ALIGNMENT__) ::operator delete(memory, std::align_val_t(alignment));
        else ::operator delete(memory);
        return;
    }
    hooks->deallocate(hooks->user, memory, bytes == 0 ? 1 : bytes);
}

}  // namespace homcull::detail
