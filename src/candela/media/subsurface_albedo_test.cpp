// The effective albedo of a subsurface medium (adding-doubling) against independent answers:
// Chandrasekhar's H-function for an index-matched, isotropically scattering half-space (the albedo for
// light along the normal is 1 - H(1) sqrt(1 - albedo)), and a plain random walk in a half-space under
// a Fresnel boundary; and its inverse.
#include "candela/media/subsurface_albedo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "candela/sampling/rng.h"

namespace candela {
namespace {

// Chandrasekhar's H(mu) for isotropic scattering of albedo w, from its fixed point
// 1 / H(mu) = sqrt(1 - w) + (w / 2) int_0^1 mu' H(mu') / (mu + mu') dmu' (midpoint rule, 200 nodes).
double chandrasekhar_h(double w, double mu) {
  constexpr int kNodes = 200;
  std::vector<double> h(kNodes, 1.0);
  auto integral = [&](double at) {
    double sum = 0;
    for (int k = 0; k < kNodes; ++k) {
      const double x = (k + 0.5) / kNodes;
      sum += x * h[k] / (at + x) / kNodes;
    }
    return sum;
  };
  for (int iteration = 0; iteration < 200; ++iteration) {
    std::vector<double> next(kNodes);
    for (int i = 0; i < kNodes; ++i) next[i] = 1 / (std::sqrt(1 - w) + 0.5 * w * integral((i + 0.5) / kNodes));
    h = next;
  }
  return 1 / (std::sqrt(1 - w) + 0.5 * w * integral(mu));
}

TEST(SubsurfaceAlbedo, IndexMatchedIsotropicHalfSpaceIsChandrasekhars) {
  for (double w : {0.3, 0.9, 0.99, 0.999}) {
    const double expected = 1 - chandrasekhar_h(w, 1) * std::sqrt(1 - w);
    EXPECT_NEAR(subsurface_effective_albedo(w, 0, 1), expected, 2e-4 * expected + 1e-6) << "albedo " << w;
  }
  EXPECT_EQ(subsurface_effective_albedo(0, 0.3, 1.5), 0);
  EXPECT_NEAR(subsurface_effective_albedo(1, 0, 1.33), 1, 1e-3);  // nothing absorbed: all comes back out
}

// A random walk in the half-space z < 0 (unit extinction) from a beam entering along -z: at the
// boundary it reflects with the Fresnel reflectance from inside, else leaves. Returns the share that
// leaves, with its standard error.
std::pair<double, double> random_walk_effective_albedo(double albedo, double g, double eta, int walks) {
  Rng rng(7, 11);
  auto fresnel = [&](double mu) {
    const double relative = 1 / eta, sin2_t = (1 - mu * mu) / (relative * relative);
    if (sin2_t >= 1) return 1.0;
    const double cos_t = std::sqrt(1 - sin2_t);
    const double rp = (relative * mu - cos_t) / (relative * mu + cos_t), rs = (mu - relative * cos_t) / (mu + relative * cos_t);
    return 0.5 * (rp * rp + rs * rs);
  };
  double sum = 0, sum2 = 0;
  for (int n = 0; n < walks; ++n) {
    double z = 0, dz = -1, weight = 1, out = 0;
    for (int event = 0; event < 100000 && weight > 1e-9; ++event) {
      double t = -std::log1p(-double(rng.next_float()));
      // Mirror at the boundary until the free path ends inside, or the walk leaves.
      bool left = false;
      while (z + dz * t > 0) {
        t -= -z / dz;
        z = 0;
        if (double(rng.next_float()) >= fresnel(dz)) {
          left = true;
          break;
        }
        dz = -dz;
      }
      if (left) {
        out = weight;
        break;
      }
      z += dz * t;
      weight *= albedo;
      // Henyey-Greenstein: the new direction's cosine with the old, then its z over a uniform azimuth.
      const double u = rng.next_float();
      double cos_theta = 1 - 2 * u;
      if (g != 0) {
        const double s = (1 - g * g) / (1 - g + 2 * g * u);
        cos_theta = (1 + g * g - s * s) / (2 * g);
      }
      const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
      const double phi = 2 * std::numbers::pi * rng.next_float();
      dz = dz * cos_theta + std::sqrt(std::max(0.0, 1 - dz * dz)) * sin_theta * std::cos(phi);
    }
    sum += out;
    sum2 += out * out;
  }
  const double mean = sum / walks;
  return {mean, std::sqrt(std::max(0.0, sum2 / walks - mean * mean) / walks)};
}

TEST(SubsurfaceAlbedo, HalfSpaceUnderAFresnelBoundaryIsTheRandomWalks) {
  struct Case {
    double albedo, g, eta;
  };
  for (Case c : {Case{0.5, 0, 1.33}, Case{0.95, 0, 1.33}, Case{0.9, 0.5, 1.5}, Case{0.8, -0.3, 1.2}}) {
    const auto [walk, error] = random_walk_effective_albedo(c.albedo, c.g, c.eta, 40000);
    EXPECT_NEAR(subsurface_effective_albedo(c.albedo, c.g, c.eta), walk, 5 * error)
        << "albedo " << c.albedo << ", g " << c.g << ", eta " << c.eta;
  }
}

TEST(SubsurfaceAlbedo, InverseGivesBackTheAlbedo) {
  for (double g : {0.0, 0.6}) {
    double previous = -1;
    for (double albedo : {0.1, 0.5, 0.9, 0.99, 0.9999}) {
      const double effective = subsurface_effective_albedo(albedo, g, 1.33);
      EXPECT_GT(effective, previous);  // increasing
      previous = effective;
      EXPECT_NEAR(subsurface_albedo_from_effective(effective, g, 1.33), albedo, 1e-5 + 1e-3 * (1 - albedo));
    }
  }
  EXPECT_EQ(subsurface_albedo_from_effective(0, 0, 1.33), 0);
  EXPECT_EQ(subsurface_albedo_from_effective(1, 0, 1.33), 1);
  EXPECT_EQ(subsurface_albedo_from_effective(2, 0, 1.33), 1);  // clamped
}

}  // namespace
}  // namespace candela
