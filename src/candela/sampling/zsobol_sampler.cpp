#include "candela/sampling/zsobol_sampler.h"

namespace candela {

ZSobolSampler::ZSobolSampler(int samples_per_set, uint64_t seed, int width, int height)
    : log2_n_(int(std::bit_width(std::bit_ceil(uint32_t(std::max(1, samples_per_set))))) - 1), seed_(seed) {
  uint32_t resolution = std::bit_ceil(uint32_t(std::max({1, width, height})));
  int log2_resolution = int(std::bit_width(resolution)) - 1;
  base4_digits_ = log2_resolution + (log2_n_ + 1) / 2;
  low_mask_ = log2_n_ == 0 ? 0 : uint32_t((uint64_t(1) << log2_n_) - 1);
  low_tables_ = std::make_shared<const LowTables>(log2_n_);
}

}  // namespace candela
