#include "candela/film/error_estimate.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace candela {

ErrorEstimate estimate_error(const Film& film, double scale_relative_error) {
  ErrorEstimate e;
  const bool splats = film.has_splats();
  const double scale = splats ? film.splat_scale() : 0;
  const double f_splat = splats ? film.splat_half_fraction() : 0.5;
  if (splats && (f_splat <= 0 || f_splat >= 1)) {
    e.why_not = "the light paths or chains are not split into two halves";
    return e;
  }
  double sum = 0, sum_sq = 0;
  uint64_t missing = 0, rendered = 0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const PixelSums& p = film.pixel(x, y);
      if (p.count == 0) continue;  // not rendered (a part, one pixel)
      ++rendered;
      const double w_a = p.half_weight, w_b = p.weight - p.half_weight;
      if (p.half_count == 0 || p.half_count == p.count || w_a == 0 || w_b == 0) {
        ++missing;
        continue;
      }
      // The pixel part's share of the weight in the first half sets the combination of the halves.
      const double f = w_a / p.weight;
      const RGB splat_all = splats ? film.splats().at(x, y) : RGB(0.0f);
      const RGB splat_a = splats ? film.half_splats().at(x, y) : RGB(0.0f);
      double pixel_error = 0;
      for (int c = 0; c < 3; ++c) {
        const double s_all = double(splat_all[c]) * scale, s_a = double(splat_a[c]) * scale;
        const double a = p.half_weighted[c] / w_a + (splats ? s_a / f_splat : 0);
        const double b = (p.weighted[c] - p.half_weighted[c]) / w_b + (splats ? (s_all - s_a) / (1 - f_splat) : 0);
        const double m = p.weighted[c] / p.weight + s_all;
        // Both parts split about evenly; the pixel sums' split weighs the difference.
        double var = f * (1 - f) * (a - b) * (a - b);
        var += scale_relative_error * scale_relative_error * s_all * s_all;
        const double truth_sq = std::max(m * m - var, std::min(a * a, b * b));
        pixel_error += var / (truth_sq + kErrorEpsilon);
      }
      pixel_error /= 3;
      sum += pixel_error;
      sum_sq += pixel_error * pixel_error;
    }
  const uint64_t covered = rendered - missing;
  // A few pixels may lack a half (adaptive sampling's pixels that got one batch); most may not.
  if (rendered == 0 || missing * 100 > rendered) {
    e.why_not = rendered == 0 ? "no pixel has samples"
                              : fmt::format("{} of {} pixels have samples in only one of the two independent halves", missing,
                                            rendered);
    return e;
  }
  e.valid = true;
  e.pixels = covered;
  const double n = double(covered);
  e.relmse = sum / n;
  const double sigma = std::sqrt(4.0 / 3.0 * sum_sq) / n;
  e.low = std::max(0.0, e.relmse - 1.96 * sigma);
  e.high = e.relmse + 1.96 * sigma;
  return e;
}

std::string describe(const ErrorEstimate& e) {
  if (!e.valid) return fmt::format("not available: {}", e.why_not);
  return fmt::format("relMSE {:.3g} (95% interval {:.3g}-{:.3g}, eps {})", e.relmse, e.low, e.high, kErrorEpsilon);
}

}  // namespace candela
