#pragma once
// The rough coat of Mitsuba 3's `roughplastic`, tabulated: how much light a rough dielectric
// interface lets through at each angle, and how much diffuse light it reflects back inside.
//
// A smooth coat transmits 1 - F(cos theta) and reflects Fdr of the diffuse light under it
// (coated_diffuse.h). Mitsuba's roughplastic instead integrates the rough interface's single
// scattering over its microfacets once per material (`parameters_changed`):
//   transmittance(mu) = integral of (1 - F(wi . m)) G1(wt) over the normals m visible from wi,
//   reflectance(mu)   = integral of F(wi . m) G1(wr) over the same,
// with wt / wr the refracted / reflected directions (Smith masking in its separable form, as
// Mitsuba weights it), by Gauss-Legendre quadrature over the visible-normal sampling square:
// 32 x 32 nodes from the outside (eta > 1), 128 x 128 from the inside, where total internal
// reflection makes the integrand kink. It tabulates the outside transmittance at 64 cosines
// mu_i = max(1e-6, i / 63), interpolated linearly, and takes the internal reflectance as
//   2 * mean_i(reflectance_inside(mu_i) mu_i),
// a 64-point mean of 2 integral R(mu) mu dmu. That mean is not the integral: with the nodes
// spaced 1/63 and divided by 64 it comes out about 2% low for glass (0.579 against 0.590 for
// eta = 1.49), which makes the diffuse base 2.6% darker than the exact series would. candela
// reproduces it exactly, because Mitsuba's references are compared pixel by pixel; scenes that
// want the smooth-Fresnel model use the default coat (see CoatedDiffuseMaterial).
#include <array>

#include <tbb/parallel_for.h>

#include "candela/materials/microfacet.h"
#include "candela/materials/specular.h"
#include "candela/math/quadrature.h"

namespace candela {

// Single-scattering albedo of a rough dielectric interface for light arriving along wi (upper
// hemisphere, eta = n_below / n_above): the energy reflected, or transmitted (without the
// eta^2 radiance scaling), integrated over the visible microfacet normals.
inline double rough_interface_albedo(const Microfacet& distribution, const Vec3& wi, float eta, bool transmitted) {
  static const QuadratureRule rule_outside = gauss_legendre(32), rule_inside = gauss_legendre(128);
  const QuadratureRule& rule = eta > 1 ? rule_outside : rule_inside;
  const int n = int(rule.nodes.size());
  double sum = 0;
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      Vec2 u(float(rule.nodes[size_t(a)] * 0.5 + 0.5), float(rule.nodes[size_t(b)] * 0.5 + 0.5));
      Vec3 m = distribution.sample_visible_normal(wi, u);
      float cos_im = dot(wi, m);
      if (!(cos_im > 0)) continue;
      float F = fresnel_dielectric(cos_im, eta);
      Vec3 wo;
      float weight;
      if (transmitted) {
        float sin2_t = (1 - cos_im * cos_im) / (eta * eta);
        if (sin2_t >= 1) continue;  // total internal reflection: nothing gets through
        float cos_t = std::sqrt(1 - sin2_t);
        wo = m * (cos_im / eta - cos_t) - wi / eta;
        if (!(wo.z < 0) || !(dot(wo, m) < 0)) continue;
        weight = 1 - F;
      } else {
        wo = m * (2 * cos_im) - wi;
        if (!(wo.z > 0)) continue;
        weight = F;
      }
      sum += double(weight * distribution.G1(wo)) * rule.weights[size_t(a)] * rule.weights[size_t(b)];
    }
  }
  return sum * 0.25;  // the nodes' square [-1, 1]^2 mapped onto [0, 1]^2
}

struct RoughCoatTable {
  static constexpr int kSize = 64;
  std::array<float, kSize> transmittance{};  // from the outside, at cos theta = i / (kSize - 1)
  float internal_reflectance = 0;            // of diffuse light from the inside

  float transmittance_at(float cos_theta) const {
    float x = std::clamp(cos_theta, 0.0f, 1.0f) * float(kSize - 1);
    int i = std::min(int(x), kSize - 2);
    float t = x - float(i);
    return (1 - t) * transmittance[size_t(i)] + t * transmittance[size_t(i + 1)];
  }
};

// About 0.1 s for GGX and 0.8 s for Beckmann (whose visible normals are sampled by Newton
// iterations) on one core; the 64 angles run in parallel and are summed in order (deterministic).
inline RoughCoatTable make_rough_coat_table(const Microfacet& distribution, float eta) {
  RoughCoatTable table;
  std::array<double, RoughCoatTable::kSize> internal{};
  tbb::parallel_for(0, RoughCoatTable::kSize, [&](int i) {
    float mu = std::max(1e-6f, float(i) / float(RoughCoatTable::kSize - 1));
    Vec3 wi(std::sqrt(1 - mu * mu), 0, mu);
    table.transmittance[size_t(i)] = float(rough_interface_albedo(distribution, wi, eta, true));
    internal[size_t(i)] = rough_interface_albedo(distribution, wi, 1 / eta, false) * mu;
  });
  double sum = 0;
  for (double v : internal) sum += v;
  table.internal_reflectance = float(2 * sum / RoughCoatTable::kSize);
  return table;
}

}  // namespace candela
