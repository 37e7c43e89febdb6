#pragma once
// Henyey-Greenstein's phase function (1941), the one pbrt-v4 and Mitsuba 3 use: a one-parameter lobe
// around the direction of travel with mean cosine g in (-1, 1); g = 0 is isotropic, g > 0 scatters
// forward. Directions follow pbrt-v4: wo points back along the incoming ray (towards the previous
// vertex), wi towards the next one, so forward scattering is wi = -wo.
#include <cmath>
#include <optional>

#include "candela/math/frame.h"
#include "candela/math/vec.h"

namespace candela {

// The density of HG per unit solid angle at cos_theta = dot(wo, wi).
inline float henyey_greenstein(float cos_theta, float g) {
  constexpr float kInv4Pi = 0.0795774715f;
  float denom = 1 + g * g + 2 * g * cos_theta;
  return kInv4Pi * (1 - g * g) / (denom * std::sqrt(std::max(denom, 1e-12f)));
}

struct PhaseSample {
  Vec3 wi;
  float pdf;  // = the phase function's value: HG is sampled exactly, so its weight is 1
};

struct HenyeyGreenstein {
  float g = 0;

  float p(const Vec3& wo, const Vec3& wi) const { return henyey_greenstein(dot(wo, wi), g); }
  float pdf(const Vec3& wo, const Vec3& wi) const { return p(wo, wi); }

  // Samples wi with density p(wo, wi) by inverting HG's cumulative distribution in the cosine
  // between wi and the direction of travel -wo.
  PhaseSample sample(const Vec3& wo, Vec2 u) const {
    float cos_travel;  // cosine between wi and -wo
    if (std::abs(g) < 1e-3f) {
      cos_travel = 1 - 2 * u.x;
    } else {
      float s = (1 - g * g) / (1 - g + 2 * g * u.x);
      cos_travel = (1 + g * g - s * s) / (2 * g);
    }
    cos_travel = std::clamp(cos_travel, -1.0f, 1.0f);
    float sin_travel = std::sqrt(std::max(0.0f, 1 - cos_travel * cos_travel));
    float phi = 2 * 3.14159265358979f * u.y;
    Frame frame(-wo);
    Vec3 wi = frame.to_world({sin_travel * std::cos(phi), sin_travel * std::sin(phi), cos_travel});
    return {wi, henyey_greenstein(-cos_travel, g)};
  }
};

}  // namespace candela
