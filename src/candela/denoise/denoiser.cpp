#include "candela/denoise/denoiser.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "candela/base/error.h"
#include "candela/base/image_buffer.h"
#include "candela/film/aov_film.h"
#include "candela/film/film.h"

namespace candela {

// Named rather than anonymous: the sanitizer CI's unity build puts this file beside error_estimate.cpp,
// whose helpers have the same names.
namespace denoiser_detail {

// The features, per pixel: albedo (3), shading normal (3), inverse depth (1). (The pixel's position
// as two more made no difference on Bitterli's scenes and cost a fifth of the time.)
constexpr int kFeatures = 7;
constexpr int kFeaturePairs = kFeatures * (kFeatures + 1) / 2;
constexpr int kTargets = 3;  // the colour's three channels
// A pixel's moments, summed over windows: F_k, F_k F_l (k <= l), Y_j, F_k Y_j.
constexpr int kMomentF = 0, kMomentFF = kFeatures, kMomentY = kMomentFF + kFeaturePairs,
              kMomentFY = kMomentY + kTargets, kMoments = kMomentFY + kFeatures * kTargets;
// Rows per strip: each strip starts its running sums afresh, so strips (not threads) fix the rounding.
constexpr int kStripRows = 64;
// The ridge added to each feature's variance in a window: relative (so that a feature's scale does
// not matter) and absolute (so that a feature constant over the window gets no weight).
constexpr double kRidgeRelative = 0.01, kRidgeAbsolute = 1e-4;
constexpr int kErrorSmoothingRadius = 5;      // the 11 x 11 box over which candidates' errors compare
constexpr int kFireflyRadius = 5;             // the 11 x 11 box whose mean bounds a firefly
constexpr float kFireflyNeighbourFactor = 2, kFireflyMeanFactor = 4;
// How far the denoiser's estimate trusts the raw halves' product A B as the truth's square (where a
// fit was chosen): by weight 1 / (1 + kRawProductTrust v), v the raw image's relative variance around
// the pixel; a half at v = 1/16, a relative standard deviation of a quarter (docs/denoising.md).
constexpr double kRawProductTrust = 16;
// The estimate's systematic uncertainty, a factor: its ratio to the true relMSE measured on seven scenes at
// 16, 32 and 64 spp lay in 0.40-1.92, 59 of 63 runs within 1.5 (docs/denoising.md).
constexpr double kSystematicFactor = 2.5;

// f(i) for every i < count, in parallel (each i on its own: the same result for any thread count).
template <class F>
void for_each_index(size_t count, const F& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, size_t(1) << 14), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) f(i);
  });
}

int feature_pair(int k, int l) {  // k <= l
  return k * kFeatures - k * (k - 1) / 2 + (l - k);
}

// Sums of `values` (`channels` floats per pixel) over the (2r+1)^2 window around each pixel (clipped
// at the image's edges), divided by the window's pixel count: separable running sums in double, rows
// and then columns each in one order, so the same for any number of threads.
ImageBuffer<float> box_mean(std::span<const float> values, int channels, int w, int h, int r) {
  const size_t row = size_t(w) * size_t(channels);
  ImageBuffer<double> along_x(values.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 16), [&](const tbb::blocked_range<int>& range) {
    std::vector<double> sum(static_cast<size_t>(channels));
    for (int y = range.begin(); y < range.end(); ++y) {
      const float* in = values.data() + size_t(y) * row;
      double* out = along_x.data() + size_t(y) * row;
      std::fill(sum.begin(), sum.end(), 0.0);
      for (int x = 0; x <= std::min(w - 1, r); ++x)
        for (int c = 0; c < channels; ++c) sum[size_t(c)] += in[size_t(x) * size_t(channels) + size_t(c)];
      for (int x = 0; x < w; ++x) {
        if (x > 0) {
          for (int c = 0; c < channels; ++c) {
            if (x + r < w) sum[size_t(c)] += in[size_t(x + r) * size_t(channels) + size_t(c)];
            if (x - r - 1 >= 0) sum[size_t(c)] -= in[size_t(x - r - 1) * size_t(channels) + size_t(c)];
          }
        }
        for (int c = 0; c < channels; ++c) out[size_t(x) * size_t(channels) + size_t(c)] = sum[size_t(c)];
      }
    }
  });
  ImageBuffer<float> mean(values.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, row, 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      const int x = int(i / size_t(channels));
      const double cols = double(std::min(w - 1, x + r) - std::max(0, x - r) + 1);
      double sum = 0;
      for (int y = 0; y <= std::min(h - 1, r); ++y) sum += along_x[size_t(y) * row + i];
      for (int y = 0; y < h; ++y) {
        if (y > 0) {
          if (y + r < h) sum += along_x[size_t(y + r) * row + i];
          if (y - r - 1 >= 0) sum -= along_x[size_t(y - r - 1) * row + i];
        }
        const double rows = double(std::min(h - 1, y + r) - std::max(0, y - r) + 1);
        mean[size_t(y) * row + i] = float(sum / (rows * cols));
      }
    }
  });
  return mean;
}

// The mean of `values` (one per pixel) over the (2r+1)^2 window around each pixel without the pixel
// itself: a pixel's choice then does not depend on its own estimated error, so that the chosen
// candidates' estimates, added up, are not biased low by the choice.
ImageBuffer<float> leave_one_out_mean(const ImageBuffer<float>& values, int w, int h, int r) {
  ImageBuffer<float> mean = box_mean(values, 1, w, h, r);
  for_each_index(size_t(w) * size_t(h), [&](size_t i) {
    const int x = int(i % size_t(w)), y = int(i / size_t(w));
    const double count = double(std::min(h - 1, y + r) - std::max(0, y - r) + 1) *
                         double(std::min(w - 1, x + r) - std::max(0, x - r) + 1);
    mean[i] = count > 1 ? float((double(mean[i]) * count - values[i]) / (count - 1)) : 0.0f;
  });
  return mean;
}

// The features of every pixel (kFeatures floats each) from one half's albedo, normal and depth;
// `median` is the median depth of the pixels that hit something (inverse depth is relative to it).
ImageBuffer<float> make_features(const DenoiseInput& in, const std::vector<float>& albedo,
                                 const std::vector<float>& normal, const std::vector<float>& depth, float median) {
  const size_t n = size_t(in.width) * size_t(in.height);
  ImageBuffer<float> f(n * kFeatures);
  tbb::parallel_for(tbb::blocked_range<int>(0, in.height, 16), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y)
      for (int x = 0; x < in.width; ++x) {
        const size_t i = size_t(y) * size_t(in.width) + size_t(x);
        float* out = &f[i * kFeatures];
        for (int c = 0; c < 3; ++c) {
          const float a = albedo[3 * i + size_t(c)], nrm = normal[3 * i + size_t(c)];
          out[c] = std::isfinite(a) ? a : 0;
          out[3 + c] = std::isfinite(nrm) ? nrm : 0;
        }
        // Inverse depth: 1 at the median depth, 0 for misses.
        const float d = depth[i];
        out[6] = std::isfinite(d) && d > 0 && d < kAovMissDepth * 0.5f ? 2 * median / (median + d) : 0;
      }
  });
  return f;
}

float median_depth(const DenoiseInput& in) {
  std::vector<float> depths;
  depths.reserve(2 * in.depth_a.size());
  for (const std::vector<float>* half : {&in.depth_a, &in.depth_b})
    for (float d : *half)
      if (std::isfinite(d) && d > 0 && d < kAovMissDepth * 0.5f) depths.push_back(d);
  if (depths.empty()) return 1;
  std::nth_element(depths.begin(), depths.begin() + std::ptrdiff_t(depths.size() / 2), depths.end());
  return std::max(depths[depths.size() / 2], 1e-6f);
}

// A window's fit: the targets' means and slopes about the features' means.
struct WindowFit {
  double mean_f[kFeatures], mean_y[kTargets], beta[kFeatures][kTargets];
  // The fit at a pixel with features `at`.
  void evaluate(const float* at, float* out) const {
    for (int j = 0; j < kTargets; ++j) {
      double value = mean_y[j];
      for (int k = 0; k < kFeatures; ++k) value += beta[k][j] * (double(at[k]) - mean_f[k]);
      out[j] = float(value);
    }
  }
};

// Windows fitted together: every step of a fit runs across the batch's windows in its innermost loop,
// which the compiler vectorises (4 doubles per instruction with AVX2, chosen at run time where the CPU
// has it; 2 with SSE2). Each window's arithmetic is the same either way: the same bytes on every CPU.
constexpr int kBatch = 8;
struct WindowBatch {
  double S[kMoments][kBatch];  // the windows' moment sums
  double count[kBatch];        // and pixel counts
};

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define CANDELA_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CANDELA_VECTOR_CLONES
#endif

// Solves the batch's regressions: the first `used` windows' fits into `fits`.
CANDELA_VECTOR_CLONES void fit_windows(const WindowBatch& batch, int used, WindowFit* fits) {
  using Lanes = double[kBatch];
  const auto& S = batch.S;
  Lanes inv, mean_f[kFeatures], mean_y[kTargets];
  for (int p = 0; p < kBatch; ++p) inv[p] = 1.0 / batch.count[p];
  for (int k = 0; k < kFeatures; ++k)
    for (int p = 0; p < kBatch; ++p) mean_f[k][p] = S[kMomentF + k][p] * inv[p];
  for (int j = 0; j < kTargets; ++j)
    for (int p = 0; p < kBatch; ++p) mean_y[j][p] = S[kMomentY + j][p] * inv[p];
  // The features' covariance over the window, with the ridge; its Cholesky factor in place (lower),
  // with the reciprocals of its diagonal (multiplying is much faster than dividing).
  Lanes L[kFeatures][kFeatures], inv_diag[kFeatures];
  for (int k = 0; k < kFeatures; ++k)
    for (int l = k; l < kFeatures; ++l)
      for (int p = 0; p < kBatch; ++p)
        L[l][k][p] = S[kMomentFF + feature_pair(k, l)][p] * inv[p] - mean_f[k][p] * mean_f[l][p];
  for (int k = 0; k < kFeatures; ++k)
    for (int p = 0; p < kBatch; ++p) L[k][k][p] += kRidgeRelative * std::max(L[k][k][p], 0.0) + kRidgeAbsolute;
  for (int k = 0; k < kFeatures; ++k) {
    Lanes d;
    for (int p = 0; p < kBatch; ++p) d[p] = L[k][k][p];
    for (int m = 0; m < k; ++m)
      for (int p = 0; p < kBatch; ++p) d[p] -= L[k][m][p] * L[k][m][p];
    for (int p = 0; p < kBatch; ++p) inv_diag[k][p] = 1.0 / std::sqrt(std::max(d[p], kRidgeAbsolute));
    for (int l = k + 1; l < kFeatures; ++l) {
      Lanes v;
      for (int p = 0; p < kBatch; ++p) v[p] = L[l][k][p];
      for (int m = 0; m < k; ++m)
        for (int p = 0; p < kBatch; ++p) v[p] -= L[l][m][p] * L[k][m][p];
      for (int p = 0; p < kBatch; ++p) L[l][k][p] = v[p] * inv_diag[k][p];
    }
  }
  // The targets' covariances with the features; solve L L^T beta = c for all targets at once.
  Lanes beta[kFeatures][kTargets];
  for (int k = 0; k < kFeatures; ++k) {
    Lanes v[kTargets];
    for (int j = 0; j < kTargets; ++j)
      for (int p = 0; p < kBatch; ++p) v[j][p] = S[kMomentFY + k * kTargets + j][p] * inv[p] - mean_f[k][p] * mean_y[j][p];
    for (int m = 0; m < k; ++m)
      for (int j = 0; j < kTargets; ++j)
        for (int p = 0; p < kBatch; ++p) v[j][p] -= L[k][m][p] * beta[m][j][p];
    for (int j = 0; j < kTargets; ++j)
      for (int p = 0; p < kBatch; ++p) beta[k][j][p] = v[j][p] * inv_diag[k][p];
  }
  for (int k = kFeatures - 1; k >= 0; --k) {
    Lanes v[kTargets];
    for (int j = 0; j < kTargets; ++j)
      for (int p = 0; p < kBatch; ++p) v[j][p] = beta[k][j][p];
    for (int m = k + 1; m < kFeatures; ++m)
      for (int j = 0; j < kTargets; ++j)
        for (int p = 0; p < kBatch; ++p) v[j][p] -= L[m][k][p] * beta[m][j][p];
    for (int j = 0; j < kTargets; ++j)
      for (int p = 0; p < kBatch; ++p) beta[k][j][p] = v[j][p] * inv_diag[k][p];
  }
  for (int p = 0; p < used; ++p) {
    WindowFit& fit = fits[p];
    for (int k = 0; k < kFeatures; ++k) fit.mean_f[k] = mean_f[k][p];
    for (int j = 0; j < kTargets; ++j) fit.mean_y[j] = mean_y[j][p];
    for (int k = 0; k < kFeatures; ++k)
      for (int j = 0; j < kTargets; ++j) fit.beta[k][j] = beta[k][j][p];
  }
}

// The moments of pixel i (features `f`, targets `targets`) into `m`.
inline void pixel_moments(const float* f, const float* targets, size_t i, double* m) {
  const float* F = f + i * kFeatures;
  const float* Y = targets + i * kTargets;
  for (int k = 0; k < kFeatures; ++k) {
    m[kMomentF + k] = F[k];
    for (int l = k; l < kFeatures; ++l) m[kMomentFF + feature_pair(k, l)] = double(F[k]) * double(F[l]);
  }
  for (int j = 0; j < kTargets; ++j) m[kMomentY + j] = Y[j];
  for (int k = 0; k < kFeatures; ++k)
    for (int j = 0; j < kTargets; ++j) m[kMomentFY + k * kTargets + j] = double(F[k]) * double(Y[j]);
}

// Moves the windows' column sums `columns` down: adds the moments of row `entering`'s pixels and takes
// off those of row `leaving` (-1: none), in one pass over the columns.
void slide_row_moments(const float* f, const float* targets, int w, int entering, int leaving,
                       std::vector<double>& columns) {
  double in[kMoments] = {}, out[kMoments] = {};
  for (int x = 0; x < w; ++x) {
    if (entering >= 0) pixel_moments(f, targets, size_t(entering) * size_t(w) + size_t(x), in);
    if (leaving >= 0) pixel_moments(f, targets, size_t(leaving) * size_t(w) + size_t(x), out);
    double* S = columns.data() + size_t(x) * kMoments;
    for (int m = 0; m < kMoments; ++m) S[m] = S[m] + in[m] - out[m];
  }
}

// Every pixel's regression over the (2r+1)^2 window around it, evaluated at the pixel: kTargets
// floats per pixel. With `stride` 2 the windows are fitted at every other pixel of every other row
// and each pixel takes the fit of the window centred at most a pixel away (a quarter of the solves;
// for the wide windows the fit hardly moves in a pixel).
ImageBuffer<float> regress(const ImageBuffer<float>& f, const ImageBuffer<float>& targets, int w, int h, int r,
                           int stride) {
  ImageBuffer<float> out(targets.size());
  const int strips = (h + kStripRows - 1) / kStripRows;  // kStripRows is a multiple of the stride
  tbb::parallel_for(tbb::blocked_range<int>(0, strips, 1), [&](const tbb::blocked_range<int>& range) {
    std::vector<double> columns(size_t(w) * kMoments);
    std::vector<WindowFit> row_fits(size_t((w + stride - 1) / stride));
    for (int strip = range.begin(); strip < range.end(); ++strip) {
      const int y0 = strip * kStripRows, y1 = std::min(h, y0 + kStripRows);
      std::fill(columns.begin(), columns.end(), 0.0);
      for (int y = std::max(0, y0 - r); y <= std::min(h - 1, y0 + r); ++y)
        slide_row_moments(f.data(), targets.data(), w, y, -1, columns);
      double S[kMoments];
      WindowBatch batch{};
      for (int p = 0; p < kBatch; ++p) batch.count[p] = 1;  // unused lanes: harmless numbers
      for (int y = y0; y < y1; ++y) {
        if (y > y0 && (y + r < h || y - r - 1 >= 0))
          slide_row_moments(f.data(), targets.data(), w, y + r < h ? y + r : -1, y - r - 1, columns);
        if ((y - y0) % stride == 0) {
          // A fitted row: the window sums along it, fitted at every stride-th pixel.
          const double rows = double(std::min(h - 1, y + r) - std::max(0, y - r) + 1);
          std::fill(S, S + kMoments, 0.0);
          for (int x = 0; x <= std::min(w - 1, r); ++x)
            for (int m = 0; m < kMoments; ++m) S[m] += columns[size_t(x) * kMoments + size_t(m)];
          int batched = 0;  // windows waiting in the batch; the first is fit number `first`
          size_t first = 0;
          for (int x = 0; x < w; ++x) {
            if (x > 0) {
              if (x + r < w)
                for (int m = 0; m < kMoments; ++m) S[m] += columns[size_t(x + r) * kMoments + size_t(m)];
              if (x - r - 1 >= 0)
                for (int m = 0; m < kMoments; ++m) S[m] -= columns[size_t(x - r - 1) * kMoments + size_t(m)];
            }
            if (x % stride != 0) continue;
            if (batched == 0) first = size_t(x / stride);
            for (int m = 0; m < kMoments; ++m) batch.S[m][batched] = S[m];
            batch.count[batched] = rows * double(std::min(w - 1, x + r) - std::max(0, x - r) + 1);
            if (++batched == kBatch) {
              fit_windows(batch, batched, &row_fits[first]);
              batched = 0;
            }
          }
          if (batched > 0) fit_windows(batch, batched, &row_fits[first]);
        }
        for (int x = 0; x < w; ++x) {
          const size_t i = size_t(y) * size_t(w) + size_t(x);
          row_fits[size_t(x / stride)].evaluate(&f[i * kFeatures], &out[i * kTargets]);
        }
      }
    }
  });
  return out;
}

// The halves as regression targets (RGB per pixel, A's and B's), each pixel-channel capped where it
// is a firefly: above both twice the brightest of its neighbours in both halves (and its own other
// half) and four times the mean of its 11 x 11 neighbourhood.
std::array<ImageBuffer<float>, 2> capped_targets(const DenoiseInput& in) {
  const int w = in.width, h = in.height;
  const size_t n = size_t(w) * size_t(h);
  ImageBuffer<float> mean_of_halves(3 * n);
  for_each_index(3 * n, [&](size_t i) { mean_of_halves[i] = 0.5f * (in.half_a[i] + in.half_b[i]); });
  const ImageBuffer<float> local = box_mean(mean_of_halves, 3, w, h, kFireflyRadius);
  std::array<ImageBuffer<float>, 2> targets{ImageBuffer<float>(3 * n), ImageBuffer<float>(3 * n)};
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 16), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        for (int half = 0; half < 2; ++half) {
          const std::vector<float>& own = half == 0 ? in.half_a : in.half_b;
          const std::vector<float>& other = half == 0 ? in.half_b : in.half_a;
          for (int c = 0; c < 3; ++c) {
            float brightest = other[3 * i + size_t(c)];
            for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
              for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
                if (xx == x && yy == y) continue;
                const size_t j = 3 * (size_t(yy) * size_t(w) + size_t(xx)) + size_t(c);
                brightest = std::max({brightest, own[j], other[j]});
              }
            const float bound =
                std::max(kFireflyNeighbourFactor * brightest, kFireflyMeanFactor * local[3 * i + size_t(c)]);
            targets[size_t(half)][3 * i + size_t(c)] = std::min(own[3 * i + size_t(c)], bound);
          }
        }
      }
  });
  return targets;
}

}  // namespace denoiser_detail

Image DenoiseInput::raw() const {
  Image image(width, height);
  for (size_t i = 0; i < size_t(width) * size_t(height); ++i)
    for (size_t c = 0; c < 3; ++c)
      image.rgb[3 * i + c] = share_a[i] * half_a[3 * i + c] + (1 - share_a[i]) * half_b[3 * i + c];
  return image;
}

void DenoiseInput::check() const {
  const size_t n = size_t(width) * size_t(height);
  bool fits = width > 0 && height > 0 && share_a.size() == n && depth_a.size() == n && depth_b.size() == n;
  for (const std::vector<float>* rgb : {&half_a, &half_b, &albedo_a, &albedo_b, &normal_a, &normal_b})
    fits = fits && rgb->size() == 3 * n;
  if (!fits) throw InternalError(fmt::format("denoise: the input's buffers do not fit a {} x {} image", width, height));
}

DenoiseResult denoise(const DenoiseInput& in) {
  using namespace denoiser_detail;
  in.check();
  const int w = in.width, h = in.height;
  const size_t n = size_t(w) * size_t(h);
  // Fit each half on its own features (DenoiseInput says why).
  const float median = median_depth(in);
  const std::array<ImageBuffer<float>, 2> features{make_features(in, in.albedo_a, in.normal_a, in.depth_a, median),
                                                   make_features(in, in.albedo_b, in.normal_b, in.depth_b, median)};
  const std::array<ImageBuffer<float>, 2> targets = capped_targets(in);

  // Radiance is not negative: the denoised image's overshoot below 0 is cut off, unless the film's
  // filter made negative pixels (a negative lobe), which the image then keeps.
  const bool any_negative = std::any_of(in.half_a.begin(), in.half_a.end(), [](float v) { return v < 0; }) ||
                            std::any_of(in.half_b.begin(), in.half_b.end(), [](float v) { return v < 0; });
  // Each candidate's filtered halves D_A, D_B (the raw image's are the halves themselves).
  auto filter = [&](int candidate) {
    std::array<ImageBuffer<float>, 2> filtered;
    for (int half = 0; half < 2; ++half) {
      if (candidate == 0) {
        const std::vector<float>& raw = half == 0 ? in.half_a : in.half_b;
        filtered[size_t(half)].assign(raw.begin(), raw.end());
        continue;
      }
      const int r = kDenoiseRadii[candidate - 1];
      filtered[size_t(half)] = regress(features[size_t(half)], targets[size_t(half)], w, h, r, r >= 5 ? 2 : 1);
    }
    return filtered;
  };
  // The widest candidate's image weighs pixels against each other in the choice (smooth, so that the
  // noisiest pixels do not dominate a neighbourhood's sum; where it blows up, the choice goes elsewhere).
  std::array<ImageBuffer<float>, 2> widest = filter(kDenoiseCandidates - 1);
  ImageBuffer<float> choice_truth(3 * n);
  for_each_index(3 * n, [&](size_t i) {
    choice_truth[i] = in.share_a[i / 3] * widest[0][i] + (1 - in.share_a[i / 3]) * widest[1][i];
  });

  std::array<ImageBuffer<float>, 2> best;
  ImageBuffer<float> best_smoothed(n), choice_error(n), mse(3 * n), best_mse(3 * n);
  // The narrowest fit's halves multiplied, and the raw image's relative variance: for the truth's square
  // in the estimate (step 5, below).
  ImageBuffer<float> narrow_fit_product(3 * n), relative_variance(3 * n);
  DenoiseResult result;
  result.choice.assign(n, 0);
  // The raw image first: a candidate replaces it only where it is estimated strictly better.
  for (int candidate = 0; candidate < kDenoiseCandidates; ++candidate) {
    std::array<ImageBuffer<float>, 2> filtered = candidate == kDenoiseCandidates - 1 ? std::move(widest) : filter(candidate);
    const ImageBuffer<float>&da = filtered[0], &db = filtered[1];
    if (candidate == 1) for_each_index(3 * n, [&](size_t i) { narrow_fit_product[i] = da[i] * db[i]; });
    // Each pixel-channel's estimated squared error of f D_A + (1 - f) D_B (denoiser.h, step 3),
    // against the capped halves for a fit (a firefly's residual would swamp the sum; the cap's
    // bias is added to the chosen fits' below), and the pixel's relative error for the choice.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i) {
        const double f = in.share_a[i];
        double relative = 0;
        for (size_t c = 0; c < 3; ++c) {
          const size_t at = 3 * i + c;
          const bool raw = candidate == 0;
          const double a = raw ? in.half_a[at] : targets[0][at], b = raw ? in.half_b[at] : targets[1][at];
          const double fa = da[at], fb = db[at], t = choice_truth[at];
          mse[at] = float((fa - a) * (fb - b) + f * (1 - f) * (fa - fb) * (fa - fb));
          relative += mse[at] / (t * t + kErrorEpsilon);
        }
        choice_error[i] = float(relative / 3);
      }
    });
    ImageBuffer<float> smoothed = leave_one_out_mean(choice_error, w, h, kErrorSmoothingRadius);
    if (candidate == 0) {
      best = std::move(filtered);
      best_mse = mse;
      best_smoothed = std::move(smoothed);
      continue;
    }
    for_each_index(n, [&](size_t i) {
      if (!(smoothed[i] < best_smoothed[i])) return;
      best_smoothed[i] = smoothed[i];
      result.choice[i] = uint8_t(candidate);
      for (int half = 0; half < 2; ++half) std::copy_n(&filtered[size_t(half)][3 * i], 3, &best[size_t(half)][3 * i]);
      std::copy_n(&mse[3 * i], 3, &best_mse[3 * i]);
    });
  }

  result.image = Image(w, h);
  for_each_index(3 * n, [&](size_t i) {
    const float f = in.share_a[i / 3];
    result.image.rgb[i] = f * best[0][i] + (1 - f) * best[1][i];
    if (!any_negative) result.image.rgb[i] = std::max(result.image.rgb[i], 0.0f);
  });
  // Its relMSE: the chosen candidates' squared errors over the truth's square, averaged.
  if (!in.has_halves) {
    result.error.why_not = "the pixels' samples are not split into two independent halves";
    return result;
  }
  // What the firefly cap took from each half, averaged over the 11 x 11 window: each an estimate of the
  // cap's bias there, so that their product estimates its square (the halves' caps are independent).
  std::array<ImageBuffer<float>, 2> removed{ImageBuffer<float>(3 * n), ImageBuffer<float>(3 * n)};
  for_each_index(3 * n, [&](size_t i) {
    removed[0][i] = in.half_a[i] - targets[0][i];
    removed[1][i] = in.half_b[i] - targets[1][i];
  });
  for (auto& r : removed) r = box_mean(r, 3, w, h, kFireflyRadius);
  // The truth's square where a fit was chosen (below): the narrowest fit's product, floored, and the
  // raw halves' product A B, floored at a quarter of it, combined geometrically with A B's weight
  // 1 / (1 + kRawProductTrust v), v the raw image's relative variance over the 11 x 11 window.
  for_each_index(3 * n, [&](size_t i) {
    const float f = in.share_a[i / 3], denoised = result.image.rgb[i], diff = in.half_a[i] - in.half_b[i];
    narrow_fit_product[i] = std::max({narrow_fit_product[i], denoised * denoised / 4, 1e-12f});
    relative_variance[i] = f * (1 - f) * diff * diff / (narrow_fit_product[i] + float(kErrorEpsilon));
  });
  relative_variance = box_mean(relative_variance, 3, w, h, kErrorSmoothingRadius);
  // Rows in parallel, their sums added in row order: the same estimate for any number of threads.
  std::vector<std::array<double, 2>> row_sums(static_cast<size_t>(h));
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); ++y) {
      double sum = 0, sum_sq = 0;
      for (size_t i = size_t(y) * size_t(w); i < size_t(y + 1) * size_t(w); ++i) {
        double relative = 0;
        for (size_t c = 0; c < 3; ++c) {
          const size_t at = 3 * i + c;
          // The truth's square, from products of two independent estimates, one from each half,
          // whose expectation is the product of theirs. Not the denoised image's square, whose
          // expectation also holds the image's variance: that variance is largest just where the
          // image's error is, and dividing by it would hide the noisiest pixels' errors (estimates
          // at 0.45-0.6 of the truth on the fog box and veach-mis). A raw pixel: A B, floored at a
          // quarter of its square (where one half has not yet found the light A B is near 0). A
          // fit: its narrowest candidate's product, which bleeds least across edges the features do
          // not show, but still bleeds (a dark pixel beside a bright one looks brighter than it
          // is, just where the fit's error is); the raw A B does not bleed but is noisy, so it
          // weighs in as far as the raw image's relative variance around the pixel is small
          // (docs/denoising.md has what each choice measured).
          const double denoised_sq = double(result.image.rgb[at]) * result.image.rgb[at];
          const double raw_product = double(in.half_a[at]) * in.half_b[at];
          double truth_sq = std::max(raw_product, denoised_sq / 4);
          if (result.choice[i] > 0) {
            const double fit_product = narrow_fit_product[at];
            const double raw_weight = 1 / (1 + kRawProductTrust * double(relative_variance[at]));
            truth_sq = std::pow(std::max(raw_product, fit_product / 4), raw_weight) * std::pow(fit_product, 1 - raw_weight);
          }
          const double cap_bias_sq = result.choice[i] > 0 ? double(removed[0][at]) * removed[1][at] : 0.0;
          relative += (best_mse[at] + cap_bias_sq) / (truth_sq + kErrorEpsilon);
        }
        sum += relative / 3;
        sum_sq += relative / 3 * relative / 3;
      }
      row_sums[size_t(y)] = {sum, sum_sq};
    }
  });
  double sum = 0, sum_sq = 0;
  for (const auto& [row_sum, row_sum_sq] : row_sums) sum += row_sum, sum_sq += row_sum_sq;
  ErrorEstimate& e = result.error;
  e.valid = true;
  e.pixels = n;
  e.relmse = std::max(0.0, sum / double(n));
  // The interval: the pixels' statistical spread (as film/error_estimate.cpp's) and the systematic factor.
  const double spread = 1.96 * std::sqrt(4.0 / 3.0 * sum_sq) / double(n);
  e.low = std::max(0.0, e.relmse / kSystematicFactor - spread);
  e.high = e.relmse * kSystematicFactor + spread;
  return result;
}

DenoiseInput denoise_input(int width, int height, const std::vector<float>& halves) {
  constexpr size_t kChannels = 21;  // the halves layer's (film/aov_film.h)
  DenoiseInput in;
  in.width = width;
  in.height = height;
  const size_t n = size_t(width) * size_t(height);
  if (halves.size() != n * kChannels)
    throw InternalError(fmt::format("denoise_input: {} values for a {} x {} halves layer", halves.size(), width, height));
  for (std::vector<float>* rgb : {&in.half_a, &in.half_b, &in.albedo_a, &in.albedo_b, &in.normal_a, &in.normal_b})
    rgb->resize(3 * n);
  in.share_a.resize(n);
  in.depth_a.resize(n);
  in.depth_b.resize(n);
  in.has_halves = false;
  for (size_t i = 0; i < n; ++i) {
    const float* px = &halves[i * kChannels];
    std::copy_n(px, 3, &in.half_a[3 * i]);
    std::copy_n(px + 3, 3, &in.half_b[3 * i]);
    in.has_halves = in.has_halves || px[0] != px[3] || px[1] != px[4] || px[2] != px[5];
    in.share_a[i] = px[6];
    std::copy_n(px + 7, 3, &in.albedo_a[3 * i]);
    std::copy_n(px + 10, 3, &in.normal_a[3 * i]);
    in.depth_a[i] = px[13];
    std::copy_n(px + 14, 3, &in.albedo_b[3 * i]);
    std::copy_n(px + 17, 3, &in.normal_b[3 * i]);
    in.depth_b[i] = px[20];
  }
  return in;
}

DenoiseInput denoise_input(const Film& film, const AovFilm& aovs) {
  if (!aovs.wants(Aov::Halves)) throw InternalError("denoise_input: the AOV film has no halves layer");
  return denoise_input(film.width(), film.height(), aovs.image(film, Aov::Halves).values);
}

}  // namespace candela
