#include "candela/film/error_estimate.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "candela/base/image_buffer.h"

namespace candela {

namespace {
constexpr double kSystematic = 0.3;
constexpr int kLocalRadius = 3;  // the 7x7 neighbourhood whose mean floors the truth
constexpr int kFireflyRadius = 5;  // the 11x11 neighbourhood whose trimmed mean floors a firefly's truth
constexpr size_t kMostDropped = 8;  // the most fireflies left out of that mean

// Per channel, the sums and counts of the values of `v` (3 values per pixel, NaN = no value) over the
// (2r+1)^2 pixels around each pixel, separably.
struct BoxSums {
  ImageBuffer<double> sums;
  ImageBuffer<double> counts;  // empty where every pixel has a value: then a window's count is its size
  int w = 0, h = 0, r = 0;
  double count(size_t at) const {
    if (!counts.empty()) return counts[at];
    const int x = int(at / 3 % size_t(w)), y = int(at / 3 / size_t(w));
    return double(std::min(h - 1, y + r) - std::max(0, y - r) + 1) *
           double(std::min(w - 1, x + r) - std::max(0, x - r) + 1);
  }
};
BoxSums box_sums(const ImageBuffer<double>& v, int w, int h, int r);

// The mean of channel c of `mean` over the (2r+1)^2 pixels around (x, y) (`box` holds their sums and
// counts), without its largest 1/24 (5 of 121): the fireflies among them.
double trimmed_local_mean(const ImageBuffer<double>& mean, const BoxSums& box, int w, int h, int x, int y, int c,
                          int r) {
  const size_t at = 3 * (size_t(y) * size_t(w) + size_t(x)) + size_t(c);
  const size_t n = size_t(box.count(at)), drop = n / 24;
  if (n == drop) return 0;
  // The `drop` largest values (at most a few): kept in descending order.
  double largest[kMostDropped];
  size_t held = 0;
  if (drop > 0) {
    for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r); ++yy)
      for (int xx = std::max(0, x - r); xx <= std::min(w - 1, x + r); ++xx) {
        const double v = mean[3 * (size_t(yy) * size_t(w) + size_t(xx)) + size_t(c)];
        if (std::isnan(v) || (held == std::min(drop, kMostDropped) && v <= largest[held - 1])) continue;
        size_t k = held < std::min(drop, kMostDropped) ? held++ : held - 1;
        for (; k > 0 && largest[k - 1] < v; --k) largest[k] = largest[k - 1];
        largest[k] = v;
      }
  }
  double dropped = 0;
  for (size_t k = 0; k < held; ++k) dropped += largest[k];
  return (box.sums[at] - dropped) / double(n - held);
}

// Whether the trimmed mean around a pixel (at `at`, own mean `own`) could raise truth_sq: without
// the scan over the window when a bound on it says not. Removing the largest values never raises a
// mean, and where no mean is negative the removed ones sum to at least the pixel's own.
bool floor_can_matter(const BoxSums& box, size_t at, double own, bool any_negative, double truth_sq) {
  const double n = box.count(at), held = std::min(std::floor(n / 24), double(kMostDropped));
  if (any_negative || held == 0 || n == held) return true;
  const double bound = (box.sums[at] - own) / (n - held);
  return bound * bound > truth_sq;
}

BoxSums box_sums(const ImageBuffer<double>& v, int w, int h, int r) {
  const size_t row = 3 * size_t(w);
  // Along x: each row's window sums, as running sums; then along y, each column's running sums.
  // Rows (then columns) in parallel, each summed in one order: the same sums for any thread count.
  // Without gaps (NaN) the counts are the windows' sizes: not summed.
  const bool gaps = std::any_of(v.begin(), v.end(), [](double value) { return std::isnan(value); });
  ImageBuffer<double> row_sums(v.size()), row_counts(gaps ? v.size() : 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 16), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y) {
      const double* in = v.data() + size_t(y) * row;
      double* sums = row_sums.data() + size_t(y) * row;
      double* counts = gaps ? row_counts.data() + size_t(y) * row : nullptr;
      for (int c = 0; c < 3; ++c) {
        auto value = [&](int x) { return in[3 * size_t(x) + size_t(c)]; };
        double sum = 0, count = 0;
        for (int x = 0; x <= std::min(w - 1, r); ++x)
          if (!std::isnan(value(x))) sum += value(x), count += 1;
        for (int x = 0; x < w; ++x) {
          if (x > 0) {
            if (x + r < w && !std::isnan(value(x + r))) sum += value(x + r), count += 1;
            if (x - r - 1 >= 0 && !std::isnan(value(x - r - 1))) sum -= value(x - r - 1), count -= 1;
          }
          sums[3 * size_t(x) + size_t(c)] = sum;
          if (gaps) counts[3 * size_t(x) + size_t(c)] = count;
        }
      }
    }
  });
  BoxSums box;
  box.w = w, box.h = h, box.r = r;
  box.sums.resize(v.size());
  box.counts.resize(gaps ? v.size() : 0);
  auto column = [&](const ImageBuffer<double>& in, ImageBuffer<double>& out, size_t i) {
    double sum = 0;
    for (int y = 0; y <= std::min(h - 1, r); ++y) sum += in[size_t(y) * row + i];
    for (int y = 0; y < h; ++y) {
      if (y > 0) {
        if (y + r < h) sum += in[size_t(y + r) * row + i];
        if (y - r - 1 >= 0) sum -= in[size_t(y - r - 1) * row + i];
      }
      out[size_t(y) * row + i] = sum;
    }
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, row, 64), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      column(row_sums, box.sums, i);
      if (gaps) column(row_counts, box.counts, i);
    }
  });
  return box;
}

// The mean of channel c of `mean` (NaN = no value) over the (2r+1)^2 pixels around (x, y), 0 where
// none has a value. Summed on demand: few pixels need it.
double local_mean(const ImageBuffer<double>& mean, int w, int h, int x, int y, int c, int r) {
  double sum = 0, count = 0;
  for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r); ++yy)
    for (int xx = std::max(0, x - r); xx <= std::min(w - 1, x + r); ++xx) {
      const double v = mean[3 * (size_t(yy) * size_t(w) + size_t(xx)) + size_t(c)];
      if (!std::isnan(v)) sum += v, count += 1;
    }
  return count > 0 ? sum / count : 0;
}
// Per pixel and channel (3 values per pixel): the mean and the variance of the mean from the
// pixel's two halves, NaN where a pixel has no samples (not rendered) or lacks a half; the lesser
// of the two halves' estimates; the variance of the splats' part alone. Also how many pixels were
// rendered and how many lack a half, and whether any mean is negative (a filter's negative lobe).
struct HalfStatistics {
  ImageBuffer<double> mean, variance, lesser_half, splat_variance;
  uint64_t missing = 0, rendered = 0;
  bool any_negative = false;
};

HalfStatistics half_statistics(const Film& film, double scale_relative_error) {
  const bool splats = film.has_splats();
  const double scale = splats ? film.splat_scale() : 0;
  const double f_splat = splats ? film.splat_half_fraction() : 0.5;
  const int w = film.width(), h = film.height();
  const size_t n = size_t(w) * size_t(h);
  HalfStatistics s;
  s.mean.assign(3 * n, std::nan(""));
  s.variance.assign(3 * n, std::nan(""));
  s.lesser_half.assign(3 * n, 0);
  s.splat_variance.assign(splats ? 3 * n : 0, 0);
  ImageBuffer<double>& mean = s.mean;
  ImageBuffer<double>& variance = s.variance;
  ImageBuffer<double>& lesser_half = s.lesser_half;
  ImageBuffer<double>& splat_variance = s.splat_variance;
  // Rows in parallel, each writing its own pixels, with its own counts.
  struct RowCounts {
    uint64_t missing = 0, rendered = 0;
    bool negative = false;
  };
  std::vector<RowCounts> row_counts(static_cast<size_t>(h));
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y) {
      RowCounts& counts = row_counts[size_t(y)];
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        const PixelSums& p = film.pixel(x, y);
        if (p.count == 0) continue;  // not rendered (a part, one pixel)
        ++counts.rendered;
        PixelHalves halves;
        if (!film.pixel_halves(x, y, halves)) {
          ++counts.missing;
          continue;
        }
        const double f = halves.share_a;
        const RGB splat_all = splats ? film.splats().at(x, y) : RGB(0.0f);
        for (int c = 0; c < 3; ++c) {
          const double s_all = double(splat_all[c]) * scale;
          const double a = halves.a[c], b = halves.b[c];
          mean[3 * i + size_t(c)] = p.weighted[c] / p.weight + s_all;
          counts.negative = counts.negative || mean[3 * i + size_t(c)] < 0;
          lesser_half[3 * i + size_t(c)] = std::min(a, b);
          if (splats) {
            const double sa = halves.splat_a[c], sb = halves.splat_b[c];
            splat_variance[3 * i + size_t(c)] = f_splat * (1 - f_splat) * (sa - sb) * (sa - sb);
          }
          variance[3 * i + size_t(c)] =
              f * (1 - f) * (a - b) * (a - b) + scale_relative_error * scale_relative_error * s_all * s_all;
        }
      }
    }
  });
  for (const RowCounts& counts : row_counts) {
    s.missing += counts.missing;
    s.rendered += counts.rendered;
    s.any_negative = s.any_negative || counts.negative;
  }
  return s;
}

// The truth's square in the denominator of channel c of pixel (x, y) (at `at` = 3 i + c), from the
// pixel's mean `s.mean` and its neighbours'.
//
// Where a rare bright path (a firefly) lifted one half, the pixel's mean is far above the truth and
// would shrink its relative error many times over: the mean is capped by the brightest of the eight
// neighbours' means. A pixel at the edge of a bright light has a bright neighbour, so its mean
// stands, and a light a pixel wide has two bright halves, which floor it. The square of the mean
// overstates the truth's square by the mean's variance, and more where the halves differ most
// (light transport's samples are skewed, so a large difference comes with a large mean): half the
// variance is taken off (all of it makes the denominator too noisy; on the Cornell box at 16 spp the
// estimate came out 0.70-0.89 of the truth with none taken off, 0.80-1.10 with half, 1.07-2.2 with
// all), but never more than half the square: in a pixel that is all noise (most paths find no
// light, a few find much, as on veach-ajar at 16 spp) the variance exceeds the square, and the
// lesser half, often 0, is no guide (the estimate was 35x the truth).
// A firefly's cap, its neighbours, can be far below the truth too, where most paths have not yet
// found the light (veach-ajar at 16 spp: a third of the pixels still black, and ten firefly
// pixel-channels with capped truths of 0.002 against true values near 1 made 42% of an estimate
// 3.9x the truth): a capped pixel's truth is floored by the mean of its 11 x 11 neighbourhood less
// that neighbourhood's own fireflies (its largest 1/24). Estimate / truth on veach-ajar at 16 spp
// 3.9-6.1 -> 1.18-1.22, at 64 spp 1.61-2.57 -> 0.98-1.20; within 0.03 elsewhere
// (docs/error-estimates.md).
// The 5th smallest of 8 values (the upper median), by Batcher's odd-even merge sorting network:
// branch-free, where std::nth_element's branches mispredict on noise.
inline double upper_median_of_8(double* v) {
  auto order = [v](int i, int j) {
    const double lo = std::min(v[i], v[j]), hi = std::max(v[i], v[j]);
    v[i] = lo, v[j] = hi;
  };
  order(0, 1), order(2, 3), order(4, 5), order(6, 7);
  order(0, 2), order(1, 3), order(4, 6), order(5, 7);
  order(1, 2), order(5, 6), order(0, 4), order(3, 7);
  order(1, 5), order(2, 6);
  order(1, 4), order(3, 6);
  order(2, 4), order(3, 5);
  order(3, 4);
  return v[4];
}

inline double truth_squared(const HalfStatistics& s, const BoxSums& firefly_box, int w, int h, int x, int y, int c,
                            size_t at) {
  const ImageBuffer<double>& mean = s.mean;
  const double own = mean[at], var = s.variance[at];
  const double lesser = s.lesser_half[at];
  double around[8];
  double brightest = -std::numeric_limits<double>::infinity();
  int k = 0;
  for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
    for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
      const size_t j = 3 * (size_t(yy) * size_t(w) + size_t(xx)) + size_t(c);
      if ((xx == x && yy == y) || std::isnan(mean[j])) continue;
      brightest = std::max(brightest, s.lesser_half[j]);
      around[k++] = mean[j];
    }
  if (k == 0) {
    brightest = own;  // no neighbour rendered
  } else {
    brightest = std::max(brightest, k == 8 ? upper_median_of_8(around) : (std::nth_element(around, around + k / 2, around + k), around[k / 2]));
  }
  const bool firefly = own > brightest;
  // Where every neighbour and both halves saw nothing yet but this pixel saw something (a
  // render so short that most paths find no light), the 7 x 7 neighbourhood's mean.
  if (brightest <= 0 && lesser <= 0) brightest = local_mean(mean, w, h, x, y, c, kLocalRadius);
  const double capped = std::max(std::min(own, brightest), lesser);
  double truth_sq = std::max({capped * capped - var / 2, capped * capped / 2, lesser * lesser});
  if (firefly && floor_can_matter(firefly_box, at, own, s.any_negative, truth_sq)) {
    const double floor = trimmed_local_mean(mean, firefly_box, w, h, x, y, c, kFireflyRadius);
    truth_sq = std::max(truth_sq, floor * floor);
  }
  return truth_sq;
}

// The pixels' relative errors (the mean over the channels of variance / (truth^2 + epsilon)) summed,
// with their squares and the splats' share, over the pixels that have both halves.
struct ErrorSums {
  double sum = 0, sum_sq = 0, splat_sum = 0;
  uint64_t covered = 0;
};

ErrorSums sum_pixel_errors(const HalfStatistics& s, bool splats, int w, int h, std::vector<double>* pixel_errors) {
  const BoxSums firefly_box = box_sums(s.mean, w, h, kFireflyRadius);
  // Rows in parallel, their sums added in row order: the same estimate for any number of threads.
  std::vector<ErrorSums> rows(static_cast<size_t>(h));
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y) {
      ErrorSums& row = rows[size_t(y)];
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        if (std::isnan(s.variance[3 * i])) continue;
        double pixel_error = 0, splat_error = 0;
        for (int c = 0; c < 3; ++c) {
          const size_t at = 3 * i + size_t(c);
          const double truth_sq = truth_squared(s, firefly_box, w, h, x, y, c, at);
          pixel_error += s.variance[at] / (truth_sq + kErrorEpsilon);
          if (splats) splat_error += s.splat_variance[at] / (truth_sq + kErrorEpsilon);
        }
        pixel_error /= 3;
        row.splat_sum += splat_error / 3;
        if (pixel_errors) (*pixel_errors)[i] = pixel_error;
        row.sum += pixel_error;
        row.sum_sq += pixel_error * pixel_error;
        ++row.covered;
      }
    }
  });
  ErrorSums total;
  for (const ErrorSums& row : rows) {
    total.sum += row.sum;
    total.sum_sq += row.sum_sq;
    total.splat_sum += row.splat_sum;
    total.covered += row.covered;
  }
  return total;
}
}  // namespace

ErrorEstimate estimate_error(const Film& film, double scale_relative_error, std::vector<double>* pixel_errors) {
  ErrorEstimate e;
  if (pixel_errors) pixel_errors->assign(size_t(film.width()) * size_t(film.height()), std::nan(""));
  const bool splats = film.has_splats();
  const double f_splat = splats ? film.splat_half_fraction() : 0.5;
  if (splats && (f_splat <= 0 || f_splat >= 1)) {
    e.why_not = "the light paths or chains are not split into two halves";
    return e;
  }
  // Each pixel's mean and variance from its two halves.
  const HalfStatistics s = half_statistics(film, scale_relative_error);
  // A few pixels may lack a half (adaptive sampling's pixels that got one batch); most may not.
  if (s.rendered == 0 || s.missing * 100 > s.rendered) {
    e.why_not = s.rendered == 0 ? "no pixel has samples"
                                : fmt::format("{} of {} pixels have samples in only one of the two independent halves",
                                              s.missing, s.rendered);
    return e;
  }
  // Each pixel's relative error, its variance over its truth's square (estimated), summed.
  const ErrorSums sums = sum_pixel_errors(s, splats, film.width(), film.height(), pixel_errors);
  e.valid = true;
  e.pixels = sums.covered;
  const double count = double(sums.covered);
  e.relmse = sums.sum / count;
  e.splat_relmse = sums.splat_sum / count;
  // The interval: the statistical spread of the pixels' one-draw estimates and of their actual
  // errors, and the estimator's systematic uncertainty from its denominators, measured against
  // converged references (docs/error-estimates.md): within kSystematic of the truth.
  const double sigma = std::sqrt(4.0 / 3.0 * sums.sum_sq) / count;
  const double half_width = std::hypot(1.96 * sigma, kSystematic * e.relmse);
  e.low = std::max(0.0, e.relmse - half_width);
  e.high = e.relmse + half_width;
  return e;
}

std::string describe(const ErrorEstimate& e) {
  if (!e.valid) return fmt::format("not available: {}", e.why_not);
  return fmt::format("relMSE {:.3g} (95% interval {:.3g}-{:.3g}, eps {})", e.relmse, e.low, e.high, kErrorEpsilon);
}

}  // namespace candela
