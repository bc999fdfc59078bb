#include "pair_cache.hpp"

#include <algorithm>
#include <utility>

namespace homcull::sort_detail {

void PairCache::reset(std::size_t objects) {
    // Sixteen slots per object, from 1,024 to 2^20 (2^20 * sizeof(PairContact), 40 MiB, at most).
    std::size_t size = 1024;
    while (size < 16 * objects && size < (std::size_t(1) << 20)) size *= 2;
    entries_.assign(size, PairContact{});
    mask_ = size - 1;
}

const PairContact* PairCache::find(std::uint32_t a, std::uint32_t b, std::uint32_t moves_a, std::uint32_t moves_b) const {
    if (entries_.empty()) return nullptr;
    if (b < a) std::swap(a, b), std::swap(moves_a, moves_b);
    const std::uint64_t key = key_of(a, b);
    const PairContact& e = entries_[index_of(key)];
    return e.key == key && e.moves_low == moves_a && e.moves_high == moves_b ? &e : nullptr;
}

PairContact& PairCache::slot(std::uint32_t a, std::uint32_t b, std::uint32_t moves_a, std::uint32_t moves_b) {
    if (b < a) std::swap(a, b), std::swap(moves_a, moves_b);
    const std::uint64_t key = key_of(a, b);
    PairContact& e = entries_[index_of(key)];
    e = PairContact{};
    e.key = key, e.moves_low = moves_a, e.moves_high = moves_b;
    return e;
}

void PairCache::clear() { std::fill(entries_.begin(), entries_.end(), PairContact{}); }

}  // namespace homcull::sort_detail
