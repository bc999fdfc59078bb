#pragma once
// Reading a fuzzer's bytes as typed values: each read takes the next bytes (zeros past the end),
// so that every input, however short, is some valid sequence of reads.
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace homcull::fuzz {

class Bytes {
public:
    Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    template <typename T>
    T take() {
        T value{};
        const std::size_t n = sizeof(T) < size_ - at_ ? sizeof(T) : size_ - at_;
        if (n > 0) std::memcpy(&value, data_ + at_, n);
        at_ += n;
        return value;
    }
    std::uint32_t below(std::uint32_t bound) { return bound ? take<std::uint32_t>() % bound : 0; }
    bool flag() { return take<std::uint8_t>() & 1u; }
    std::size_t left() const { return size_ - at_; }
    const std::uint8_t* rest() const { return data_ + at_; }

private:
    const std::uint8_t* data_;
    std::size_t size_, at_ = 0;
};

}  // namespace homcull::fuzz
