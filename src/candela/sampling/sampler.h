#pragma once
// Independent uniform samples. Each (pixel, sample index, seed) gets its own PCG32 stream, so a
// sample's random numbers do not depend on which thread renders it or in what order.
#include "candela/math/vec.h"
#include "candela/sampling/rng.h"

namespace candela {

class IndependentSampler {
 public:
  explicit IndependentSampler(uint64_t seed) : seed_(seed) {}
  void start_pixel_sample(int x, int y, uint64_t sample_index) {
    rng_.set_sequence(hash_values(uint64_t(x), uint64_t(y), seed_), mix_bits(sample_index));
  }
  float get_1d() { return rng_.next_float(); }
  Vec2 get_2d() {
    float a = rng_.next_float();
    return {a, rng_.next_float()};
  }
  Vec2 get_pixel_2d() { return get_2d(); }

 private:
  uint64_t seed_;
  Rng rng_;
};

}  // namespace candela
