#pragma once
// What the hull test learned about two objects that have not moved since: Snyder and
// Lengyel's coherence, for scenes whose objects mostly stand still while the eye moves.
//
// Two hulls that meet make each able to hide the other from any eye (each meets the region
// between the eye and the other), and two that a plane parts stay parted while neither moves:
// an eye on the far side of that plane from one of them cannot see the other in front of it.
// So the first test of a pair of still objects runs GJK on the two hulls alone and keeps the
// answer; later frames answer from it in a few operations, or fall back to the full test (an
// eye on the near side, or GJK not settled).
//
// A PairSlots table made with the sorter; an entry holds the objects' move counts, so a moved
// object makes its entries stale.
#include <homcull/detail/memory.hpp>

#include <glm/glm.hpp>

#include <algorithm>
#include <cstdint>

namespace homcull::sort_detail {

// A direct-mapped table of fixed size keyed by pairs of objects: an entry is overwritten by any
// other pair landing on its slot. `Entry` has a `std::uint64_t key`, 0 when empty. No
// allocation after reset().
template <class Entry>
class PairSlots {
public:
    // `per_object` slots per object, from 1,024 to 2^20 (a power of two).
    void reset(std::size_t objects, std::size_t per_object) {
        std::size_t size = 1024;
        while (size < per_object * objects && size < (std::size_t(1) << 20)) size *= 2;
        entries_.assign(size, Entry{});
        shift_ = 64;
        for (std::size_t s = size; s > 1; s /= 2) --shift_;
    }
    void clear() { std::fill(entries_.begin(), entries_.end(), Entry{}); }
    bool empty() const { return entries_.empty(); }
    // The key of the ordered pair (first, second); never 0.
    static std::uint64_t key_of(std::uint32_t first, std::uint32_t second) { return (std::uint64_t(first) << 32 | second) + 1; }
    // The slot a key lands on (holding that key's entry, another's or none).
    Entry& operator[](std::uint64_t key) { return entries_[index_of(key)]; }
    const Entry& operator[](std::uint64_t key) const { return entries_[index_of(key)]; }

private:
    // Fibonacci hashing (Knuth, TAOCP vol. 3, 6.4): the top bits of the product, which every
    // bit of the key reaches. (Lower bits miss the first id of the pair: its bits start at 32.)
    std::size_t index_of(std::uint64_t key) const { return std::size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
    detail::Vector<Entry> entries_;
    int shift_ = 64;
};

struct PairContact {
    std::uint64_t key = 0;  // 0: empty
    std::uint32_t moves_low = 0, moves_high = 0;  // of the lower and the higher object id
    std::uint8_t contact = 0;  // Contact (hull_occlusion.hpp)
    // Apart: the lower-id object lies in dot(normal, x) <= below, the higher one in >= above.
    glm::vec3 normal{0.0f};
    float below = 0, above = 0;
};

class PairCache {
public:
    void reset(std::size_t objects);  // sized for this many objects (at construction)
    // The entry of the pair {a, b} made with these move counts, or null.
    const PairContact* find(std::uint32_t a, std::uint32_t b, std::uint32_t moves_a, std::uint32_t moves_b) const;
    // The slot for the pair (to fill in): key and move counts set, contact to be written.
    PairContact& slot(std::uint32_t a, std::uint32_t b, std::uint32_t moves_a, std::uint32_t moves_b);
    void clear();

private:
    PairSlots<PairContact> slots_;  // keyed by (lower id, higher id)
};

}  // namespace homcull::sort_detail
