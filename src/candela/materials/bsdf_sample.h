#pragma once
#include "candela/materials/bsdf_flags.h"
#include "candela/math/color.h"
#include "candela/math/vec.h"

namespace candela {

struct BsdfSample {
  Vec3 wi;          // local frame
  RGB weight;       // f |cos theta_i| / pdf: the factor the path throughput is multiplied by
  float pdf = 0;    // solid-angle density of wi for non-delta samples; for delta samples the discrete
                    // probability of the chosen event (only used to skip MIS)
  bool is_delta = false;
  float eta = 1;    // relative index of refraction crossed (1 for reflection); for Russian roulette
  // Continues straight on without scattering (wi = -wo: a mask's absent part, a thin sheet's
  // transmission): Mitsuba's "null" events, which its volumetric path tracer does not count as a
  // bounce and which shadow rays see through.
  bool passes_through = false;
};

inline float cos_theta(const Vec3& w) { return w.z; }
inline float abs_cos_theta(const Vec3& w) { return std::abs(w.z); }
inline bool same_hemisphere(const Vec3& a, const Vec3& b) { return a.z * b.z > 0; }

}  // namespace candela
