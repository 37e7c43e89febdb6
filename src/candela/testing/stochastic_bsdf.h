#pragma once
// Statistical checks of stochastic BSDFs (BsdfFlags::Stochastic: the layered BSDFs), whose eval()
// and pdf() are random-walk estimates, so that the exact checks of the BSDF contract (sample weight
// = eval |cos| / pdf for each sample) cannot hold sample by sample.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "candela/materials/bsdf.h"
#include "candela/sampling/rng.h"
#include "candela/testing/statistics.h"

namespace candela::testing {

// Sets the seed of a stochastic BSDF (other BSDFs have none).
inline void set_bsdf_seed(Bsdf& bsdf, uint32_t seed) {
  std::visit(
      [&](auto& b) {
        if constexpr (has(std::decay_t<decltype(b)>::flags, BsdfFlags::Stochastic)) b.seed = seed;
      },
      bsdf);
}

struct StochasticWeightTest {
  double p_value = 1;
  int cells = 0;                             // cells compared
  double sample_total = 0, eval_total = 0;   // the two estimates of the non-delta albedo
  double total_standard_error = 0;           // of their difference
  double worst_z = 0;                        // the largest |difference| / standard error of a cell
};

// Two independent Monte Carlo estimates, per cell of a grid over wo's hemisphere (uniform in
// |cos theta| and in phi), of the integral of f |cos| over the cell:
//   from sample(): the mean over `samples` draws of the weight of the non-delta samples that land
//     in the cell (0 elsewhere): unbiased for it when sample()'s weights are;
//   from eval():   the cell's solid angle times the mean of f |cos| at `evals_per_cell` directions
//     drawn uniformly in the cell, each eval() with a seed of its own (averaged over seeds).
// The weights' channel mean is compared. The statistic sum over cells of (difference / standard
// error)^2, each standard error estimated from the two samples, is chi-square distributed with one
// degree of freedom per cell when the two agree; cells where neither estimate has 50 non-zero
// terms are left out. Deterministic for a given `seed`.
inline StochasticWeightTest stochastic_weight_test(const Bsdf& bsdf, const Vec3& wo, int samples, int evals_per_cell,
                                                   uint64_t seed, int theta_bins = 6, int phi_bins = 8) {
  const float side = wo.z < 0 ? -1.0f : 1.0f;
  const int cells = theta_bins * phi_bins;
  auto cell_of = [&](const Vec3& w) {
    float z = std::clamp(w.z * side, 0.0f, 1.0f);
    int ti = std::min(theta_bins - 1, int(z * float(theta_bins)));
    float phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi;
    int pi = std::min(phi_bins - 1, int(phi / (2 * kPi) * float(phi_bins)));
    return ti * phi_bins + pi;
  };
  struct Sums {
    double sum = 0, sum2 = 0;
    int nonzero = 0;
  };
  std::vector<Sums> from_samples(static_cast<size_t>(cells)), from_evals(static_cast<size_t>(cells));
  Rng rng(seed, 0x5ea);
  for (int i = 0; i < samples; ++i) {
    float u_lobe = rng.next_float();
    Vec2 u(rng.next_float(), rng.next_float());
    auto s = bsdf_sample(bsdf, wo, u_lobe, u);
    if (!s || s->is_delta || s->wi.z * side <= 0) continue;
    double v = s->weight.average();
    Sums& c = from_samples[size_t(cell_of(s->wi))];
    c.sum += v;
    c.sum2 += v * v;
    c.nonzero += v != 0;
  }
  Bsdf seeded = bsdf;
  const double cell_solid_angle = (1.0 / theta_bins) * (2 * kPi / phi_bins);
  for (int ti = 0; ti < theta_bins; ++ti)
    for (int pi = 0; pi < phi_bins; ++pi) {
      Sums& c = from_evals[size_t(ti * phi_bins + pi)];
      for (int j = 0; j < evals_per_cell; ++j) {
        float z = (float(ti) + rng.next_float()) / float(theta_bins);
        float phi = 2 * kPi * (float(pi) + rng.next_float()) / float(phi_bins);
        float r = std::sqrt(std::max(0.0f, 1 - z * z));
        Vec3 wi(r * std::cos(phi), r * std::sin(phi), z * side);
        set_bsdf_seed(seeded, rng.next_u32());
        double v = double(bsdf_eval(seeded, wo, wi).average()) * z * cell_solid_angle;
        c.sum += v;
        c.sum2 += v * v;
        c.nonzero += v != 0;
      }
    }
  StochasticWeightTest out;
  double chi2 = 0, total_variance = 0;
  for (int k = 0; k < cells; ++k) {
    const Sums &a = from_samples[size_t(k)], &b = from_evals[size_t(k)];
    double mean_a = a.sum / samples, var_a = std::max(0.0, a.sum2 / samples - mean_a * mean_a) / samples;
    double mean_b = b.sum / evals_per_cell,
           var_b = std::max(0.0, b.sum2 / evals_per_cell - mean_b * mean_b) / evals_per_cell;
    out.sample_total += mean_a;
    out.eval_total += mean_b;
    total_variance += var_a + var_b;
    if (std::max(a.nonzero, b.nonzero) < 50 || !(var_a + var_b > 0)) continue;
    double z2 = (mean_a - mean_b) * (mean_a - mean_b) / (var_a + var_b);
    chi2 += z2;
    out.worst_z = std::max(out.worst_z, std::sqrt(z2));
    ++out.cells;
  }
  out.total_standard_error = std::sqrt(total_variance);
  out.p_value = out.cells > 0 ? gamma_q(out.cells / 2.0, chi2 / 2.0) : 1.0;
  return out;
}

}  // namespace candela::testing
