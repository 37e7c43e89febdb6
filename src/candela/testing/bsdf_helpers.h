#pragma once
// Directions, the Monte Carlo albedo and the microfacet normalisation integrals shared by the BSDF tests.
#include <cmath>
#include <vector>

#include "candela/materials/bsdf.h"
#include "candela/math/vec.h"
#include "candela/sampling/rng.h"
#include "candela/sampling/warp.h"
#include "candela/testing/bsdf_chi_square.h"
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

// The smooth refraction of wo into a medium of relative IOR eta: the centre of a rough transmission lobe.
inline Vec3 refracted(const Vec3& wo, float eta = 1.5f) {
  Vec3 wt;
  float eta_rel;
  refract_local(wo, eta, wt, eta_rel);
  return wt;
}

// Rough glass (IOR 1.5) seen from outside, for the chi-square tests of every distribution: the
// roughness, the incident angle and a binning that resolves both lobes there. Refraction into the
// denser medium compresses the transmitted lobe (to about alpha / 3 at normal incidence), so these
// need more magnification than reflection does; at oblique incidence the bins are centred on the
// smooth refraction direction.
struct RoughGlassCase {
  float alpha_x, alpha_y, theta;
  Binning binning;
};
inline std::vector<RoughGlassCase> rough_glass_from_outside() {
  const Vec3 up(0, 0, 1);
  return {{0.2f, 0.2f, 0, {up, 6, -1, 12}},
          {0.2f, 0.2f, 80, {up, 1, -1, 24}},
          {0.6f, 0.6f, 45, {refracted(direction(45)), 3, -1, 24}},
          {0.6f, 0.6f, 88, {refracted(direction(88)), 2, -1, 24}},
          {0.1f, 0.4f, 45, {refracted(direction(45)), 5, -1, 24}}};
}

// Integrals over the hemisphere of a microfacet distribution's projected area, D(wm) cos(theta_m),
// and of its density of normals visible from w, D_w(wm): both are 1 when normalised. The polar angle
// is integrated on an nu x nphi grid that is dense near the pole (theta = pi/2 u^2).
struct NormalIntegrals {
  double projected = 0, visible = 0;
};
template <typename Distribution>
NormalIntegrals normal_integrals(const Distribution& d, const Vec3& w, int nu, int nphi) {
  NormalIntegrals sum;
  for (int i = 0; i < nu; ++i) {
    double u = (i + 0.5) / nu, theta = kPi / 2 * u * u, dtheta = kPi * u / nu;
    for (int j = 0; j < nphi; ++j) {
      double phi = 2 * kPi * (j + 0.5) / nphi;
      Vec3 wm(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
      double dw = std::sin(theta) * dtheta * 2 * kPi / nphi;
      sum.projected += d.D(wm) * wm.z * dw;
      sum.visible += d.D(w, wm) * (dot(w, wm) > 0 ? 1 : 0) * dw;
    }
  }
  return sum;
}

}  // namespace candela::testing
