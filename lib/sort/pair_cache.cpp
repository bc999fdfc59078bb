#include "pair_cache.hpp"

#include <utility>

namespace homcull::sort_detail {

void PairCache::reset(std::size_t objects) { slots_.reset(objects, 16); }

const PairContact* PairCache::find(std::uint32_t a, std::uint32_t b, std::uint32_t moves_a, std::uint32_t moves_b) const {
    if (slots_.empty()) return nullptr;
    if (b < a) std::swap(a, b), std::swap(moves_a, moves_b);
    const std::uint64_t key = slots_.key_of(a, b);
    const PairContact& e = slots_[key];
    return e.key == key && e.moves_low == moves_a && e.moves_high == moves_b ? &e : nullptr;
}

PairContact& PairCache::slot(std::uint32_t a, std::uint32_t b, std::uint32_t moves_a, std::uint32_t moves_b) {
    if (b < a) std::swap(a, b), std::swap(moves_a, moves_b);
    const std::uint64_t key = slots_.key_of(a, b);
    PairContact& e = slots_[key];
    e = PairContact{};
    e.key = key, e.moves_low = moves_a, e.moves_high = moves_b;
    return e;
}

void PairCache::clear() { slots_.clear(); }

}  // namespace homcull::sort_detail
