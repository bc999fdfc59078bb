#pragma once
// Where the library's containers get their memory. By default from operator new, as any C++
// code; the C interface (homcull.h) makes its objects inside a MemoryScope holding the engine's
// allocator, and every container made there keeps that allocator for its whole life (a stateful
// allocator, as std::pmr's), whichever thread later grows or frees it. Tasks run through the
// caller's job system carry the caller's scope (common/run_tasks.hpp). So every byte an object of
// the C interface uses comes from the engine, by construction: the containers have no other way
// to allocate.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace homcull::detail {

struct MemoryHooks {
    // Null, or size bytes aligned to `alignment` (at most 64): null means out of memory.
    void* (*allocate)(void* user, std::size_t size, std::size_t alignment) = nullptr;
    void (*deallocate)(void* user, void* memory, std::size_t size) = nullptr;  // size: as allocated
    void* user = nullptr;
};

// The hooks containers made on this thread take now (null: operator new).
const MemoryHooks* current_memory_hooks() noexcept;

// Makes `hooks` current on this thread for its lifetime, then restores the previous ones.
class MemoryScope {
public:
    explicit MemoryScope(const MemoryHooks* hooks) noexcept;
    ~MemoryScope();
    MemoryScope(const MemoryScope&) = delete;
    MemoryScope& operator=(const MemoryScope&) = delete;

private:
    const MemoryHooks* previous_;
};

// From the hooks (std::bad_alloc when they return null), or operator new without hooks.
void* hooked_allocate(const MemoryHooks* hooks, std::size_t bytes, std::size_t alignment);
void hooked_deallocate(const MemoryHooks* hooks, void* memory, std::size_t bytes, std::size_t alignment) noexcept;

template <typename T>
class HookAllocator {
public:
    using value_type = T;
    using propagate_on_container_copy_assignment = std::true_type;
    using propagate_on_container_move_assignment = std::true_type;
    using propagate_on_container_swap = std::true_type;
    using is_always_equal = std::false_type;

    HookAllocator() noexcept : hooks_(current_memory_hooks()) {}
    template <typename U>
    HookAllocator(const HookAllocator<U>& other) noexcept : hooks_(other.hooks()) {}

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_alloc();
        return static_cast<T*>(hooked_allocate(hooks_, n * sizeof(T), alignof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept { hooked_deallocate(hooks_, p, n * sizeof(T), alignof(T)); }
    const MemoryHooks* hooks() const noexcept { return hooks_; }

    template <typename U>
    bool operator==(const HookAllocator<U>& o) const noexcept { return hooks_ == o.hooks(); }
    template <typename U>
    bool operator!=(const HookAllocator<U>& o) const noexcept { return hooks_ != o.hooks(); }

private:
    const MemoryHooks* hooks_;
};

// The library's vector: std::vector with the hooks current where it was made.
template <typename T>
using Vector = std::vector<T, HookAllocator<T>>;

// reserve() with the room's pages written now: a vector reserved for a frame's worst case and
// first filled during a frame would take the page faults of that fill in the frame. Its
// elements stay as they were.
template <typename V>
void reserve_written(V& v, std::size_t n) {
    const std::size_t size = v.size();
    if (n > size) v.resize(n);
    v.resize(size);  // shrinking keeps the capacity
}

// A single object from the hooks current where it was made, freed into the same.
struct HookDeleter {
    const MemoryHooks* hooks = nullptr;
    template <typename T>
    void operator()(T* p) const noexcept {
        p->~T();
        hooked_deallocate(hooks, p, sizeof(T), alignof(T));
    }
};
template <typename T>
using HookPtr = std::unique_ptr<T, HookDeleter>;

template <typename T, typename... Args>
HookPtr<T> make_hooked(Args&&... args) {
    const MemoryHooks* hooks = current_memory_hooks();
    void* memory = hooked_allocate(hooks, sizeof(T), alignof(T));
    try {
        return HookPtr<T>(new (memory) T(std::forward<Args>(args)...), HookDeleter{hooks});
    } catch (...) {
        hooked_deallocate(hooks, memory, sizeof(T), alignof(T));
        throw;
    }
}

}  // namespace homcull::detail
