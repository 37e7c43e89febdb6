#include "candela/testing/statistics.h"

#include <cmath>

#include "candela/sampling/rng.h"

namespace candela::testing {

double gamma_q(double a, double x) {
  // Numerical Recipes: series for x < a + 1, continued fraction otherwise.
  if (x <= 0) return 1;
  double gln = std::lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1 / a, del = sum;
    for (int n = 0; n < 10000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1 / 1e-300, d = 1 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

double chi_square_p_value(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi2 = 0, pooled_obs = 0, pooled_exp = 0;
  int dof = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++dof;
  }
  if (pooled_exp >= 5) {
    chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++dof;
  } else if (pooled_obs > 5 + 10 * pooled_exp) {
    return 0;  // many samples where the pdf says there should be (almost) none
  }
  dof -= 1;
  if (dof < 1) return 1;
  return gamma_q(dof / 2.0, chi2 / 2.0);
}

double spherical_chi_square_p_value(const std::function<Vec3(Vec2)>& sample,
                                    const std::function<float(const Vec3&)>& pdf, int samples, uint64_t seed,
                                    float z_min, int theta_bins, int phi_bins, int integration_resolution) {
  const size_t below_cell = size_t(theta_bins * phi_bins);
  const double z_range = 1.0 - z_min;
  auto cell_of = [&](const Vec3& w) -> size_t {
    float z = std::clamp(w.z, -1.0f, 1.0f);
    if (z < z_min) return below_cell;
    int ti = std::min(theta_bins - 1, int((z - z_min) / z_range * theta_bins));
    float phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi;
    int pi = std::min(phi_bins - 1, int(phi / (2 * kPi) * phi_bins));
    return size_t(ti * phi_bins + pi);
  };
  std::vector<double> observed(below_cell + 1, 0), expected(observed.size(), 0);
  Rng rng(seed, 12345);
  for (int i = 0; i < samples; ++i) {
    Vec3 w = sample({rng.next_float(), rng.next_float()});
    if (!is_finite(w) || length_squared(w) == 0) continue;  // rejected samples carry no direction
    observed[cell_of(normalize(w))] += 1;
  }
  // Integrate the pdf by a midpoint rule on a fine sub-grid of each cell (dz dphi is exactly solid
  // angle); the region below z_min is integrated on a coarser grid of its own.
  auto integrate = [&](double z0, double z1, double phi0, double phi1, int sub) {
    double sum = 0;
    for (int a = 0; a < sub; ++a)
      for (int b = 0; b < sub; ++b) {
        double z = z0 + (z1 - z0) * (a + 0.5) / sub;
        double phi = phi0 + (phi1 - phi0) * (b + 0.5) / sub;
        double r = std::sqrt(std::max(0.0, 1 - z * z));
        sum += pdf(Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
      }
    return sum / (sub * sub) * (z1 - z0) * (phi1 - phi0);
  };
  for (int ti = 0; ti < theta_bins; ++ti)
    for (int pi = 0; pi < phi_bins; ++pi)
      expected[size_t(ti * phi_bins + pi)] =
          samples * integrate(z_min + z_range * ti / theta_bins, z_min + z_range * (ti + 1) / theta_bins,
                              2 * kPi * pi / phi_bins, 2 * kPi * (pi + 1) / phi_bins, integration_resolution);
  if (z_min > -1) expected[below_cell] = samples * integrate(-1, z_min, 0, 2 * kPi, 200);
  return chi_square_p_value(observed, expected);
}

}  // namespace candela::testing
