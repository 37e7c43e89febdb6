#pragma once
// Owen-scrambled Sobol' samples in Morton (Z) order over the image (Ahmed & Wonka 2020, "Screen-space
// blue-noise diffusion of Monte Carlo sampling error via hierarchical ordering of pixels"; pbrt-v4's
// ZSobolSampler). Pixel (x, y)'s samples are one aligned block of 2^m consecutive indices of the
// Sobol' (0,2)-sequence, at block number Morton(x, y), so they form a (0,m,2)-net, and neighbouring
// pixels' blocks are neighbours in the sequence, so their union is a net too. The index is randomised
// per dimension so that aligned blocks still map onto aligned blocks, to decorrelate pixels and
// dimensions: the pixel's base-4 digits are permuted level by level (each permutation chosen by the
// digits above it, as pbrt-v4 does), the sample's own log2(n) bits get a nested (Owen) scramble in
// base 2 seeded by the pixel; and each dimension gets its own Owen scrambling of the sample value. Every dimension, the pixel position included, uses Sobol'
// dimensions 0 and 1 only, with those two different randomisations.
//
// All pixels share each dimension's scramble (that is what lets neighbouring pixels' samples form a
// joint net), so within one image the pixels' sets take only a few coarse shapes: one image's error
// depends more on its seed than with per-pixel randomisation; over seeds it is that of Owen-scrambled
// nets, and unbiased.
//
// Sample indices >= n (the set size, rounded up to a power of two) continue in set k = index / n:
// the same construction with every permutation and scramble reseeded by k, so each set is an
// independently randomised (0,m,2)-net and sets are statistically independent of one another.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <vector>

#include "candela/math/vec.h"
#include "candela/sampling/rng.h"

namespace candela {

namespace sobol {

inline constexpr int kMatrixColumns = 64;  // one column per bit of a 64-bit sample index
using GeneratorMatrix = std::array<uint32_t, kMatrixColumns>;

// Sobol' dimension 0: the van der Corput sequence, i.e. the bit-reversal matrix (column j = 2^-(j+1)).
constexpr GeneratorMatrix van_der_corput_matrix() {
  GeneratorMatrix m{};
  for (int j = 0; j < 32; ++j) m[size_t(j)] = 1u << (31 - j);
  return m;
}

// Sobol' dimension 1: primitive polynomial x + 1 (degree 1) with initial direction number m_1 = 1;
// Bratley & Fox's recurrence m_k = 2 m_{k-1} xor m_{k-1} gives the direction numbers v_k = m_k / 2^k
// (Pascal's triangle mod 2). Column j holds v_{j+1} as a 0.32 fixed-point fraction; its bits below
// 2^-32 are dropped.
constexpr GeneratorMatrix pascal_matrix() {
  GeneratorMatrix m{};
  uint64_t direction = 1;  // m_1; bit b of m_{j+1} weighs 2^(b - j - 1)
  for (int j = 0; j < kMatrixColumns; ++j) {
    m[size_t(j)] = j <= 31 ? uint32_t(direction << (31 - j)) : uint32_t(direction >> (j - 31));
    direction = (direction << 1) ^ direction;
  }
  return m;
}

inline constexpr std::array<GeneratorMatrix, 2> kMatrices = {van_der_corput_matrix(), pascal_matrix()};

// The unscrambled sample as a 0.32 fixed-point fraction: the product of the generator matrix with
// the index's bits over GF(2). Done a byte of the index at a time with precomputed XORs of 8 columns
// (8 table lookups instead of a loop over up to 64 bits: this is on the hot path).
using ByteTables = std::array<std::array<uint32_t, 256>, kMatrixColumns / 8>;
constexpr ByteTables byte_tables(const GeneratorMatrix& m) {
  ByteTables t{};
  for (int byte = 0; byte < kMatrixColumns / 8; ++byte)
    for (int value = 0; value < 256; ++value) {
      uint32_t v = 0;
      for (int bit = 0; bit < 8; ++bit)
        if (value & (1 << bit)) v ^= m[size_t(8 * byte + bit)];
      t[size_t(byte)][size_t(value)] = v;
    }
  return t;
}
inline const std::array<ByteTables, 2> kByteTables = {byte_tables(kMatrices[0]), byte_tables(kMatrices[1])};

inline uint32_t sample_bits(uint64_t index, int dimension) {
  const ByteTables& t = kByteTables[size_t(dimension)];
  uint32_t v = 0;
  for (int byte = 0; index != 0; index >>= 8, ++byte) v ^= t[size_t(byte)][index & 0xff];
  return v;
}

constexpr uint32_t reverse_bits32(uint32_t v) {
  v = (v << 16) | (v >> 16);
  v = ((v & 0x00ff00ffu) << 8) | ((v & 0xff00ff00u) >> 8);
  v = ((v & 0x0f0f0f0fu) << 4) | ((v & 0xf0f0f0f0u) >> 4);
  v = ((v & 0x33333333u) << 2) | ((v & 0xccccccccu) >> 2);
  v = ((v & 0x55555555u) << 1) | ((v & 0xaaaaaaaau) >> 1);
  return v;
}

// Hash-based Owen scrambling (Laine & Karras 2011; Burley 2020 "Practical Hash-based Owen
// Scrambling", pbrt-v4's FastOwenScrambler). On bit-reversed values, each step (adding or
// multiplying, v ^= v * even) changes a bit only as a function of the bits below it; reversed back,
// that flips each digit as a function of the digits above it: a nested (Owen) scramble, which maps
// elementary intervals onto elementary intervals and so keeps the net property.
constexpr uint32_t owen_steps(uint32_t reversed, uint32_t seed) {
  uint32_t v = reversed;
  v ^= v * 0x3d20adeau;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * 0x05526c56u;
  v ^= v * 0x53a22864u;
  return v;
}
constexpr uint32_t fast_owen_scramble(uint32_t v, uint32_t seed) {
  return reverse_bits32(owen_steps(reverse_bits32(v), seed));
}

// 24 high bits to a float in [0, 1): exact, so never rounds up to 1.
constexpr float bits_to_unit_float(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

}  // namespace sobol

// Interleaves the bits of x (even positions) and y (odd positions).
constexpr uint64_t encode_morton2(uint32_t x, uint32_t y) {
  auto spread = [](uint64_t v) {
    v = (v | (v << 16)) & 0x0000ffff0000ffffULL;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffULL;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0fULL;
    v = (v | (v << 2)) & 0x3333333333333333ULL;
    v = (v | (v << 1)) & 0x5555555555555555ULL;
    return v;
  };
  return spread(x) | (spread(y) << 1);
}

// All 24 permutations of {0, 1, 2, 3}, permutation p decoded from its Lehmer code (p / 6, p / 2 % 3, p % 2).
constexpr std::array<std::array<uint8_t, 4>, 24> base4_digit_permutations() {
  std::array<std::array<uint8_t, 4>, 24> table{};
  for (int p = 0; p < 24; ++p) {
    std::array<uint8_t, 4> remaining = {0, 1, 2, 3};
    int choices[3] = {p / 6, p / 2 % 3, p % 2};
    for (int slot = 0; slot < 4; ++slot) {
      int pick = slot < 3 ? choices[slot] : 0;
      table[size_t(p)][size_t(slot)] = remaining[size_t(pick)];
      for (int k = pick; k < 3 - slot; ++k) remaining[size_t(k)] = remaining[size_t(k + 1)];
    }
  }
  return table;
}
inline constexpr auto kBase4DigitPermutations = base4_digit_permutations();

class ZSobolSampler {
 public:
  // `width` x `height` sets the Morton resolution (the next power of two of the larger side); pixels
  // outside it still get valid samples (their extra Morton bits pass through unpermuted).
  ZSobolSampler(int samples_per_set, uint64_t seed, int width, int height);

  // Dimensions from this one on come from a PCG stream per (pixel, sample, seed) instead: they are
  // the deep bounces of a path, where stratification gains little and the scrambled sample (three
  // hashes per 2D draw) would cost more than the path itself. The first 32 cover the pixel (and the lens
  // and time, where they are drawn) and the first two path vertices (light choice and point, lobe, direction, roulette), or the
  // first vertex with up to 8 shadow rays.
  static constexpr int kScrambledDimensions = 32;

  // With replicas, samples [8k, 8k + 8) belong to replica k % 2, and each replica is the whole
  // construction above on its own, its sets reseeded apart from the other's: two independent
  // randomisations of the sequence, each with its nets intact (an error estimate needs
  // independent halves; SamplerDesc::replicas). In blocks of 8 so that the per-pixel work kept
  // between samples is redone only every 8 samples.
  static constexpr uint64_t kReplicaBlock = 8;
  void set_replicas(bool on) { replicas_ = on; }

  void start_pixel_sample(int x, int y, uint64_t sample_index) {
    // The PCG stream of the deep dimensions is seeded when the first one is drawn (many paths end
    // before): set_sequence costs two hashes.
    rng_pixel_ = {x, y};
    rng_sample_ = sample_index;
    rng_seeded_ = false;
    uint64_t replica = 0;
    if (replicas_) {
      replica = (sample_index / kReplicaBlock) & 1;
      sample_index = (sample_index / (2 * kReplicaBlock)) * kReplicaBlock + sample_index % kReplicaBlock;
    }
    uint64_t set = ((sample_index >> log2_n_) << (replicas_ ? 1 : 0)) | replica;
    uint64_t index_in_set = sample_index & ((uint64_t(1) << log2_n_) - 1);
    uint64_t pixel_code = encode_morton2(uint32_t(x), uint32_t(y));
    morton_index_ = (pixel_code << log2_n_) | index_in_set;
    low_reversed_ = log2_n_ == 0 ? 0 : sobol::reverse_bits32(uint32_t(index_in_set)) >> (32 - log2_n_);
    // The permuted digits above the sample index depend only on the pixel, the set and the
    // dimension: keep them while the same pixel's samples are drawn one after another. The
    // dimensions' hashes and scramble seeds depend on the set alone. With replicas a pixel's samples
    // alternate between two sets every 8 samples: each replica keeps its own (the set's low bit is
    // the replica), so that neither is recomputed at every switch (8% of a render at 16 spp a pass).
    cache_index_ = int(set & (replicas_ ? 1 : 0));
    SetCache& cache = caches_[size_t(cache_index_)];
    if (set != cache.set) {
      uint64_t set_seed = hash_values(seed_, set);
      for (int d = 0; d < kScrambledDimensions; ++d) {
        cache.dimension_hashes[size_t(d)] = hash_values(set_seed, uint64_t(d));
        cache.scramble_seeds[size_t(d)] = scramble_seeds(cache.dimension_hashes[size_t(d)]);
      }
    }
    if (pixel_code != cache.pixel || set != cache.set) {
      cache.pixel = pixel_code;
      cache.set = set;
      cache.dimensions = 0;
    }
    dimension_ = 0;
  }

  float get_1d() {
    if (dimension_ >= kScrambledDimensions) return deep_rng().next_float();
    const int d = dimension_++;
    const PixelPart& pixel = pixel_part(d);
    const uint32_t low = scrambled_low_index(pixel.low_seed);
    return scrambled_sample(pixel.sobol_reversed[0] ^ low_tables_->product_reversed(low, 0),
                            uint32_t(caches_[size_t(cache_index_)].scramble_seeds[size_t(d)]));
  }

  Vec2 get_2d() {
    if (dimension_ + 1 >= kScrambledDimensions) {
      Rng& rng = deep_rng();
      float a = rng.next_float();
      return {a, rng.next_float()};
    }
    const int d = dimension_;
    dimension_ += 2;
    const PixelPart& pixel = pixel_part(d);
    const uint32_t low = scrambled_low_index(pixel.low_seed);
    const uint64_t seeds = caches_[size_t(cache_index_)].scramble_seeds[size_t(d)];
    return {scrambled_sample(pixel.sobol_reversed[0] ^ low_tables_->product_reversed(low, 0), uint32_t(seeds)),
            scrambled_sample(pixel.sobol_reversed[1] ^ low_tables_->product_reversed(low, 1), uint32_t(seeds >> 32))};
  }

  Vec2 get_pixel_2d() { return get_2d(); }

  int samples_per_set() const { return 1 << log2_n_; }

 private:
  // Owen scrambling seeds of a dimension (pair), hashed apart from the digit permutations' hashes.
  static uint64_t scramble_seeds(uint64_t dimension_hash) { return hash_values(dimension_hash); }
  // The Owen-scrambled sample from its Sobol' bits, given bit-reversed (as owen_steps wants them).
  static float scrambled_sample(uint32_t reversed_bits, uint32_t seed) {
    return sobol::bits_to_unit_float(sobol::reverse_bits32(sobol::owen_steps(reversed_bits, seed)));
  }

  // One of the 24 digit permutations for a node of the digit tree: a cheap multiplicative hash,
  // reduced to [0, 24) by multiply-shift.
  static uint32_t permutation_choice(uint64_t key) {
    uint64_t h = (key ^ (key >> 29)) * 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 32;
    return uint32_t((uint64_t(uint32_t(h)) * 24) >> 32);
  }

  // The sample's index in the Sobol' sequence is the Morton index (pixel code, then the sample's
  // log2(n) bits), randomised so that aligned blocks map onto aligned blocks. The Sobol' product is
  // linear over GF(2), so it splits at bit log2(n) into the pixel's part and the sample's part.
  //
  // The pixel's part of dimension d: its base-4 digits randomly permuted, top digit first, each by
  // one of the 24 permutations of {0,1,2,3} chosen by hashing the dimension and the digits above it
  // (pbrt-v4's ZSobol), multiplied by both Sobol' matrices (kept bit-reversed); and the seed of the
  // sample part's scramble. Computed at the pixel's first sample that uses d and kept while the same
  // pixel's samples follow one another.
  struct PixelPart {
    uint32_t sobol_reversed[2];
    uint32_t low_seed;
  };
  const PixelPart& pixel_part(int d) {
    const uint64_t bit = uint64_t(1) << d;
    SetCache& cache = caches_[size_t(cache_index_)];
    PixelPart& part = cache.pixel_parts[size_t(d)];
    if (!(cache.dimensions & bit)) {
      const uint64_t dimension_hash = cache.dimension_hashes[size_t(d)];
      const int first_pixel_digit = (log2_n_ + 1) / 2;  // digit i spans bits 2i - odd, 2i - odd + 1
      const uint64_t high = permuted_pixel_digits(dimension_hash, first_pixel_digit);
      part.sobol_reversed[0] = sobol::reverse_bits32(sobol::sample_bits(high, 0));
      part.sobol_reversed[1] = sobol::reverse_bits32(sobol::sample_bits(high, 1));
      part.low_seed = uint32_t(hash_values(dimension_hash, morton_index_ >> log2_n_));
      cache.dimensions |= bit;
    }
    return part;
  }

  // The sample's part: its log2(n) bits under a nested (Owen) scramble in base 2, seeded by the pixel
  // and the dimension, so each bit is flipped as a function of the bits above it. Worked on the
  // bit-reversed index (most significant bit at bit 0, as owen_steps wants it), which
  // start_pixel_sample reverses once for all dimensions; the result stays reversed, and
  // LowTables multiplies it by the Sobol' matrices in that order.
  uint32_t scrambled_low_index(uint32_t seed) const {
    return sobol::owen_steps(low_reversed_, seed) & low_mask_;
  }

  // The Sobol' products (bit-reversed) of the sample part given bit-reversed, a byte at a time.
  struct LowTables {
    std::vector<std::array<uint32_t, 256>> bytes[2];
    explicit LowTables(int log2_n) {
      for (int dim = 0; dim < 2; ++dim)
        for (int byte = 0; byte * 8 < log2_n; ++byte) {
          std::array<uint32_t, 256> table{};
          for (uint32_t value = 0; value < 256; ++value) {
            uint32_t product = 0;
            for (int b = 0; b < 8; ++b) {
              const int reversed_bit = 8 * byte + b;  // weighs bit log2_n - 1 - reversed_bit of the index
              if ((value >> b & 1) && reversed_bit < log2_n)
                product ^= sobol::sample_bits(uint64_t(1) << (log2_n - 1 - reversed_bit), dim);
            }
            table[value] = sobol::reverse_bits32(product);
          }
          bytes[dim].push_back(table);
        }
    }
    uint32_t product_reversed(uint32_t low, int dim) const {
      uint32_t v = 0;
      for (size_t byte = 0; low != 0; low >>= 8, ++byte) v ^= bytes[dim][byte][low & 0xff];
      return v;
    }
  };

  // Digits lo.. of the Morton index, each permuted by one of the 24 permutations of {0,1,2,3} chosen
  // by hashing the dimension and the digits above it, and the bits above all permuted digits, passed
  // through.
  uint64_t permuted_pixel_digits(uint64_t dimension_hash, int lo) const {
    const int odd = (log2_n_ & 1) != 0 ? 1 : 0;
    const int permuted_bits = 2 * base4_digits_ - odd;
    uint64_t index = permuted_bits >= 64 ? 0 : (morton_index_ >> permuted_bits) << permuted_bits;
    for (int i = base4_digits_ - 1; i >= lo; --i) {
      int shift = 2 * i - odd;
      uint32_t digit = uint32_t(morton_index_ >> shift) & 3u;
      uint64_t higher_digits = shift + 2 >= 64 ? 0 : morton_index_ >> (shift + 2);
      const auto& permutation = kBase4DigitPermutations[permutation_choice(higher_digits ^ dimension_hash)];
      index |= uint64_t(permutation[digit]) << shift;
    }
    return index;
  }

  int log2_n_;
  bool replicas_ = false;
  int base4_digits_;  // permuted digits: log2(resolution) + ceil(log2(n) / 2)
  uint64_t seed_;
  uint64_t morton_index_ = 0;
  uint32_t low_reversed_ = 0;  // the sample's log2(n) index bits, reversed
  uint32_t low_mask_ = 0;      // 2^log2(n) - 1
  std::shared_ptr<const LowTables> low_tables_;  // shared by the copies a render makes per tile
  int dimension_ = 0;
  Rng& deep_rng() {
    if (!rng_seeded_) {
      rng_.set_sequence(hash_values(uint64_t(rng_pixel_[0]), uint64_t(rng_pixel_[1]), seed_), mix_bits(rng_sample_));
      rng_seeded_ = true;
    }
    return rng_;
  }
  Rng rng_;
  std::array<int, 2> rng_pixel_{};
  uint64_t rng_sample_ = 0;
  bool rng_seeded_ = false;
  // What start_pixel_sample keeps for a set and a pixel; one per replica.
  struct SetCache {
    uint64_t pixel = ~uint64_t(0), set = ~uint64_t(0);
    uint64_t dimensions = 0;  // bit d: pixel_parts[d] is valid
    std::array<PixelPart, kScrambledDimensions> pixel_parts{};
    std::array<uint64_t, kScrambledDimensions> dimension_hashes{}, scramble_seeds{};
  };
  std::array<SetCache, 2> caches_;
  int cache_index_ = 0;  // the current sample's
};

}  // namespace candela
