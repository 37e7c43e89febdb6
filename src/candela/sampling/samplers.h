#pragma once
// The pixel samplers (the paper's sec. 4.3 plus pbrt-v4's ZSobol) as one closed set: the integrator
// is a template over the sampler type and the render loop dispatches with std::visit once per tile.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <variant>

#include "candela/sampling/poisson_sampler.h"
#include "candela/sampling/sampler.h"
#include "candela/sampling/stratified_sampler.h"
#include "candela/sampling/zsobol_sampler.h"
#include "candela/description/scene_desc.h"

namespace candela {

using Sampler = std::variant<IndependentSampler, StratifiedSampler, PoissonSampler, ZSobolSampler>;

// Applies X to every alternative of Sampler, e.g. for explicit instantiations of sampler templates.
#define CANDELA_FOR_EACH_SAMPLER(X) X(IndependentSampler) X(StratifiedSampler) X(PoissonSampler) X(ZSobolSampler)

// `samples_per_set` n: stratification holds within each block of n consecutive sample indices (the
// spp of a plain render, the batch size of adaptive sampling); ZSobol rounds n up to a power of two.
// `width` x `height` is the image resolution (ZSobol's Morton order).
inline Sampler make_sampler(const SamplerDesc& desc, int samples_per_set, uint64_t seed, int width, int height) {
  switch (desc.type) {
    case SamplerType::Stratified: return StratifiedSampler(samples_per_set, desc.jitter, seed);
    case SamplerType::Poisson: return PoissonSampler(samples_per_set, seed);
    case SamplerType::ZSobol: {
      // Each replica draws half the samples.
      ZSobolSampler z(desc.replicas ? (samples_per_set + 1) / 2 : samples_per_set, seed, width, height);
      z.set_replicas(desc.replicas);
      return z;
    }
    case SamplerType::Independent: break;
  }
  return IndependentSampler(seed);
}

// Which half of a pixel's samples sample i falls in (film.h: two independent estimates of the
// pixel): the first when (i / block) is even. Independent samples alternate; sets of a set-based
// sampler are independently randomised, so they alternate; ZSobol's replicas alternate every 8
// samples (so a ZSobol render needs 16 spp for an estimate). Without replicas a ZSobol or
// stratified render of one set has no second half.
inline uint64_t half_block(const SamplerDesc& desc, int samples_per_set) {
  switch (desc.type) {
    case SamplerType::Independent: return 1;
    case SamplerType::ZSobol:
      return desc.replicas ? ZSobolSampler::kReplicaBlock
                           : uint64_t(std::bit_ceil(unsigned(std::max(1, samples_per_set))));
    case SamplerType::Stratified:
    case SamplerType::Poisson: break;
  }
  return uint64_t(std::max(1, samples_per_set));
}

}  // namespace candela
