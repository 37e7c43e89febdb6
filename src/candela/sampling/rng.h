#pragma once
// PCG32 (O'Neill 2014) and the hashing used to give every (pixel, sample, seed) its own stream,
// which is what makes renders independent of the thread count.
#include <cstdint>

namespace candela {

// 64-bit finaliser of MurmurHash3 / splitmix64: a good avalanche mixer.
constexpr uint64_t mix_bits(uint64_t v) {
  v ^= v >> 31;
  v *= 0x7fb5d329728ea185ULL;
  v ^= v >> 27;
  v *= 0x81dadef4bc2dd44dULL;
  v ^= v >> 33;
  return v;
}

constexpr uint64_t hash_values(uint64_t a) { return mix_bits(a + 0x9e3779b97f4a7c15ULL); }
template <typename... Rest>
constexpr uint64_t hash_values(uint64_t a, Rest... rest) {
  return mix_bits(hash_values(a) ^ (hash_values(static_cast<uint64_t>(rest)...) * 0xbf58476d1ce4e5b9ULL));
}

class Rng {
 public:
  Rng() = default;
  Rng(uint64_t sequence, uint64_t seed) { set_sequence(sequence, seed); }
  void set_sequence(uint64_t sequence, uint64_t seed) {
    state_ = 0u;
    inc_ = (sequence << 1u) | 1u;
    next_u32();
    state_ += seed;
    next_u32();
  }
  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 0x5851f42d4c957f2dULL + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  // Uniform float in [0, 1): 24 random mantissa bits, never rounds up to 1.
  float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_ = 0x853c49e6748fea9bULL, inc_ = 0xda3e39cb94b95bdbULL;
};

}  // namespace candela
