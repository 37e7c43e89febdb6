#pragma once
// Stratified ("padded and shuffled") samples, as pbrt-v4's StratifiedSampler: every dimension (1D)
// or dimension pair (2D) of a set of n consecutive sample indices is split into n strata, each sample
// gets one stratum through a random permutation private to (pixel, set, dimension, seed), and is
// jittered inside it. Shuffling the strata independently per dimension decorrelates the dimensions,
// so any number of dimensions can be stratified without the n^d samples of a full grid.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "candela/math/vec.h"
#include "candela/sampling/rng.h"

namespace candela {

// Element i of a pseudo-random permutation of {0, ..., n-1} chosen by `seed`, evaluated without
// building the permutation (Kensler 2013, "Correlated Multi-Jittered Sampling"). Step 1: a keyed hash
// that is a bijection on [0, 2^b) (key xor, odd multiplications and xorshifts, all masked to b bits)
// is applied repeatedly until the value lands inside [0, n): cycle walking, which keeps a bijection.
// Step 2: a rotation by a further hash of the seed, mod n, makes each element uniform over seeds.
inline uint32_t permutation_element(uint32_t i, uint32_t n, uint64_t seed) {
  if (n <= 1) return 0;
  const uint32_t mask = std::bit_ceil(n) - 1;
  const int half_bits = std::max(1, int(std::bit_width(mask)) / 2);
  const uint32_t key0 = uint32_t(seed), key1 = uint32_t(seed >> 32);
  do {
    i = ((i ^ key0) * 0x9e3779b1u) & mask;
    i ^= i >> half_bits;
    i = ((i + key1) * 0x85ebca6bu) & mask;
    i ^= i >> 1;
    i = ((i ^ (key1 >> 16)) * 0xc2b2ae35u) & mask;
    i ^= i >> half_bits;
    i = ((i ^ (key0 >> 16)) * 0x27d4eb2fu) & mask;
    i ^= i >> 1;
  } while (i >= n);
  return uint32_t((i + mix_bits(seed) % n) % n);
}

// Columns of the 2D strata grid, nx x ny = n: nx is the largest divisor of n not above sqrt(n), so
// strata are as square as n allows (16 -> 4 x 4, 8 -> 2 x 4, 12 -> 3 x 4; a prime n gives 1 x n).
inline int stratified_grid_columns(int n) {
  int nx = std::max(1, int(std::sqrt(double(n))));
  while (nx * nx > n) --nx;  // guard against sqrt rounding up
  while (n % nx != 0) --nx;
  return nx;
}

// The point (stratum + offset) / strata, kept strictly inside its stratum (and so below 1) even when
// float rounding of the sum would carry it onto the next stratum's lower edge.
inline float point_in_stratum(uint32_t stratum, float offset, uint32_t strata) {
  float upper_edge = float(stratum + 1) / float(strata);
  return std::min((float(stratum) + offset) / float(strata), std::nextafter(upper_edge, 0.0f));
}

class StratifiedSampler {
 public:
  // `samples_per_set` = n (the strata count); `jitter` false puts every sample at its stratum's centre.
  StratifiedSampler(int samples_per_set, bool jitter, uint64_t seed)
      : n_(uint32_t(std::max(1, samples_per_set))),
        columns_(uint32_t(stratified_grid_columns(int(n_)))),
        rows_(n_ / columns_),
        jitter_(jitter),
        seed_(seed) {}

  void start_pixel_sample(int x, int y, uint64_t sample_index) {
    set_hash_ = hash_values(uint64_t(x), uint64_t(y), sample_index / n_, seed_);
    index_in_set_ = uint32_t(sample_index % n_);
    dimension_ = 0;
    // The jitter comes from the sample's own PCG stream, as IndependentSampler's numbers do.
    if (jitter_) rng_.set_sequence(hash_values(uint64_t(x), uint64_t(y), seed_), mix_bits(sample_index));
  }

  float get_1d() {
    uint32_t stratum = permuted_stratum();
    dimension_ += 1;
    return point_in_stratum(stratum, jitter_offset(), n_);
  }

  Vec2 get_2d() {
    uint32_t stratum = permuted_stratum();
    dimension_ += 2;
    float dx = jitter_offset(), dy = jitter_offset();
    return {point_in_stratum(stratum % columns_, dx, columns_), point_in_stratum(stratum / columns_, dy, rows_)};
  }

  Vec2 get_pixel_2d() { return get_2d(); }

 private:
  // This sample's stratum in the current dimension: the set's shuffle applied to its index in the set.
  uint32_t permuted_stratum() const {
    return permutation_element(index_in_set_, n_, hash_values(set_hash_, uint64_t(dimension_)));
  }
  float jitter_offset() { return jitter_ ? rng_.next_float() : 0.5f; }

  uint32_t n_, columns_, rows_;
  bool jitter_;
  uint64_t seed_;
  uint64_t set_hash_ = 0;
  uint32_t index_in_set_ = 0;
  int dimension_ = 0;
  Rng rng_;
};

}  // namespace candela
