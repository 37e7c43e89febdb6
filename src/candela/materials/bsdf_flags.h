#pragma once
// What a BSDF type can do, stated by each BSDF of the closed list (bsdf.h) as
//   static constexpr BsdfFlags flags
// (as pbrt-v4's BxDFFlags, but per type: what any instance may do, whatever its parameters; what a
// given instance does is has_non_delta() and the other members of the contract). Code outside a
// BSDF asks these flags instead of testing for particular types.
#include <cstdint>

namespace candela {

enum class BsdfFlags : uint8_t {
  None = 0,               // scatters nothing whatever its parameters: paths end on it
  Reflection = 1 << 0,    // may scatter to wo's side of the surface
  Transmission = 1 << 1,  // may scatter to the other side
  Delta = 1 << 2,         // may have delta (specular) lobes, reached only by sample()
  NonDelta = 1 << 3,      // may have non-delta lobes (eval and pdf not zero)
  // Its non-delta transmission crosses an interface of relative IOR `eta` (a float member,
  // n_inside / n_outside): radiance is scaled by 1 / eta'^2 there and importance is not, so the
  // adjoint differs from eval (bsdf_adjoint_scale).
  Refraction = 1 << 4,
  // eval() and pdf() are Monte Carlo estimates (layered BSDFs: random walks through the layers),
  // each a fixed function of its arguments and the BSDF's seed: unbiased for f, and for pdf an
  // approximation that multiple importance sampling can use; sample()'s weight is unbiased for
  // f |cos| / density but is not eval() |cos| / pdf() of any one call.
  Stochastic = 1 << 5,
  // f(wo, wi) and f(wi, wo) differ beyond refraction's scale (hair: its attenuation and azimuths
  // follow wo): the adjoint BSDF evaluates it with the directions swapped (bsdf_eval_adjoint).
  NonReciprocal = 1 << 6,
};

constexpr BsdfFlags operator|(BsdfFlags a, BsdfFlags b) { return BsdfFlags(uint8_t(a) | uint8_t(b)); }
// Whether `set` has any of the flags `f`.
constexpr bool has(BsdfFlags set, BsdfFlags f) { return (uint8_t(set) & uint8_t(f)) != 0; }
// Neither reflects nor transmits.
constexpr bool is_black(BsdfFlags set) { return !has(set, BsdfFlags::Reflection | BsdfFlags::Transmission); }

}  // namespace candela
