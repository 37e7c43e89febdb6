#pragma once
// The BSDF contract. Every BSDF works in the local shading frame (normal = +z, directions point away
// from the surface: wo towards the viewer, wi towards the light) and offers
//   eval(wo, wi)                 f(wo, wi) of the non-delta parts (without the cosine)
//   pdf(wo, wi)                  solid-angle density with which sample() produces wi (non-delta parts)
//   sample(wo, u_lobe, u)        a direction with weight f |cos| / pdf, or nothing when the path is absorbed
//   has_non_delta()              whether light sampling can help at all
//   has_non_delta_transmission() whether the non-delta parts also scatter to the side opposite wo
//                                (rough dielectrics, diffuse transmission): then light must be sampled,
//                                and directions drawn, on both sides of the surface
//   non_delta_probability(wo)    the probability that sample() picks a non-delta lobe for this wo; a
//                                BSDF picks its non-delta lobes exactly when u_lobe < non_delta_probability(wo),
//                                which lets the integrator swap in another direction-sampling strategy for them
//   static constexpr flags       what the type can do, whatever its parameters (bsdf_flags.h)
// A Stochastic BSDF (layered.h) estimates eval() and pdf() by random walks: each call is a fixed
// function of its arguments and the BSDF's seed, eval() unbiased for f; its sample weights match
// eval() |cos| / density in expectation only.
// Radiance-carrying (camera) paths are assumed: refraction scales radiance by 1 / eta^2, and
// BsdfSample::eta reports the relative IOR crossed.
// The closed list of BSDFs is the variant `Bsdf`; dispatch happens once, here.
#include <optional>
#include <variant>

#include "candela/materials/coated_diffuse.h"
#include "candela/materials/conductor.h"
#include "candela/materials/dielectric.h"
#include "candela/materials/diffuse.h"
#include "candela/materials/diffuse_transmission.h"
#include "candela/materials/hair.h"
#include "candela/materials/layered.h"
#include "candela/materials/phong.h"
#include "candela/materials/principled.h"
#include "candela/materials/specular.h"

namespace candela {

using Bsdf = std::variant<DiffuseBsdf, PhongBsdf, MirrorBsdf, DielectricBsdf, BlackBsdf, ConductorBsdf,
                          CoatedDiffuseBsdf, DiffuseTransmissionBsdf, PrincipledBsdf, PrincipledThinBsdf,
                          LayeredDiffuseBsdf, LayeredConductorBsdf, HairBsdf>;

inline RGB bsdf_eval(const Bsdf& b, const Vec3& wo, const Vec3& wi) {
  return std::visit([&](const auto& x) { return x.eval(wo, wi); }, b);
}
inline float bsdf_pdf(const Bsdf& b, const Vec3& wo, const Vec3& wi) {
  return std::visit([&](const auto& x) { return x.pdf(wo, wi); }, b);
}
inline std::optional<BsdfSample> bsdf_sample(const Bsdf& b, const Vec3& wo, float u_lobe, Vec2 u) {
  return std::visit([&](const auto& x) { return x.sample(wo, u_lobe, u); }, b);
}
inline bool bsdf_has_non_delta(const Bsdf& b) {
  return std::visit([](const auto& x) { return x.has_non_delta(); }, b);
}
inline bool bsdf_has_non_delta_transmission(const Bsdf& b) {
  return std::visit([](const auto& x) { return x.has_non_delta_transmission(); }, b);
}
inline float bsdf_non_delta_probability(const Bsdf& b, const Vec3& wo) {
  return std::visit([&](const auto& x) { return x.non_delta_probability(wo); }, b);
}
// Paths that carry importance (traced from the lights) need the adjoint BSDF f*(wo, wi) = f(wi, wo).
// Every BSDF here is symmetric except in refraction, where radiance is scaled by 1 / eta'^2 and
// importance is not (Veach 1997, sec. 5.2): the factor that turns eval() into the adjoint for a
// transmitted pair (wo the direction the path arrived from), for the BSDFs whose flags say their
// non-delta transmission refracts (BsdfFlags::Refraction). Sampled refractions report eta' in
// BsdfSample::eta and are scaled by eta'^2 the same way.
inline float bsdf_adjoint_scale(const Bsdf& b, const Vec3& wo, const Vec3& wi) {
  if (wo.z * wi.z >= 0) return 1;
  return std::visit(
      [&](const auto& x) -> float {
        if constexpr (has(std::decay_t<decltype(x)>::flags, BsdfFlags::Refraction)) {
          float etap = wo.z > 0 ? x.eta : 1 / x.eta;
          return etap * etap;
        } else {
          return 1;
        }
      },
      b);
}
// The adjoint BSDF f*(wo, wi) = f(wi, wo) itself (wo the direction the path arrived from): eval()
// times bsdf_adjoint_scale, or, for BSDFs that are not reciprocal (BsdfFlags::NonReciprocal),
// eval() with the directions swapped.
inline RGB bsdf_eval_adjoint(const Bsdf& b, const Vec3& wo, const Vec3& wi) {
  return std::visit(
      [&](const auto& x) -> RGB {
        if constexpr (has(std::decay_t<decltype(x)>::flags, BsdfFlags::NonReciprocal)) {
          return x.eval(wi, wo);
        } else {
          return x.eval(wo, wi) * bsdf_adjoint_scale(b, wo, wi);
        }
      },
      b);
}
// The BSDF's flags (bsdf_flags.h): what its type can do.
inline BsdfFlags bsdf_flags(const Bsdf& b) {
  return std::visit([](const auto& x) { return std::decay_t<decltype(x)>::flags; }, b);
}
// Scatters nothing whatever the directions.
inline bool bsdf_is_black(const Bsdf& b) { return is_black(bsdf_flags(b)); }

}  // namespace candela
