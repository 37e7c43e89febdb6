#pragma once
// What kind of emitter a light type is, stated by each light of the closed list (light.h) as
//   static constexpr LightFlags flags
// (pbrt-v4's LightType, as flags). Code outside a light asks these flags (light.h's light_is_delta,
// light_is_at_infinity, ...) instead of testing for particular types.
#include <cstdint>

namespace candela {

enum class LightFlags : uint8_t {
  None = 0,
  DeltaPosition = 1 << 0,   // emits from a single point (point, spot, projector lights)
  DeltaDirection = 1 << 1,  // emits along a single direction, from infinity (distant lights)
  Area = 1 << 2,            // emits from a surface that rays can hit (emissive shapes)
  // Surrounds the scene at infinity: rays that escape the scene see it, through radiance(dir)
  // (sky and environment lights).
  Infinite = 1 << 3,
};

constexpr LightFlags operator|(LightFlags a, LightFlags b) { return LightFlags(uint8_t(a) | uint8_t(b)); }
// Whether `set` has any of the flags `f`.
constexpr bool has(LightFlags set, LightFlags f) { return (uint8_t(set) & uint8_t(f)) != 0; }

}  // namespace candela
