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
// A direct-mapped table of fixed size, made with the sorter: a pair's entry is overwritten by
// any other pair landing on its slot, and holds the objects' move counts, so a moved object
// makes its entries stale. No allocation after construction.
#include <homcull/detail/memory.hpp>

#include <glm/glm.hpp>

#include <cstdint>

namespace homcull::sort_detail {

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
    static std::uint64_t key_of(std::uint32_t low, std::uint32_t high) { return (std::uint64_t(low) << 32 | high) + 1; }
    std::size_t index_of(std::uint64_t key) const { return std::size_t((key * 0x9E3779B97F4A7C15ull) >> 20) & mask_; }
    detail::Vector<PairContact> entries_;
    std::size_t mask_ = 0;
};

}  // namespace homcull::sort_detail
