#pragma once
// Directions and the Monte Carlo albedo shared by the BSDF tests.
#include <cmath>

#include "candela/materials/bsdf.h"
#include "candela/math/vec.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/statistics.h"

namespace candela::testing {

// The unit direction at polar angle theta (from +z) and azimuth phi, in degrees.
inline Vec3 direction(float theta_degrees, float phi_degrees = 30) {
  float t = radians(theta_degrees), p = radians(phi_degrees);
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}
// w mirrored through the surface (the tangent plane z = 0).
inline Vec3 below(const Vec3& w) { return {w.x, w.y, -w.z}; }

// Uniformly distributed direction on the sphere.
inline Vec3 random_direction(Rng& rng) { return square_to_uniform_sphere({rng.next_float(), rng.next_float()}); }

// Monte Carlo directional albedo: the mean of the sample weights (green channel). Refraction's
// 1 / eta^2 radiance scaling is undone, so the result is the fraction of energy scattered.
inline Estimate albedo(const Bsdf& bsdf, const Vec3& wo, int n = 100000, Rng rng = Rng(7, 99)) {
  return sample_mean(n, [&] {
    auto s = bsdf_sample(bsdf, wo, rng.next_float(), {rng.next_float(), rng.next_float()});
    return s ? double(s->weight.g) * s->eta * s->eta : 0.0;
  });
}

}  // namespace candela::testing
